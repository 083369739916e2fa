#include "huge_pages.hpp"

#include "own_path.hpp"

#include <unistd.h>

#include <cstdlib>
#include <fstream>

namespace lamina::cli {

std::optional<std::string> huge_page_tunables(const HugePageInputs& in) {
  if (in.sanitized) return std::nullopt;
  if (in.command != "check" && in.command != "slice" && in.command != "plan") return std::nullopt;
  if (in.opt_out && std::string_view(in.opt_out) == "0") return std::nullopt;
  const std::string_view current = in.tunables ? in.tunables : "";
  if (current.find("glibc.malloc.hugetlb") != std::string_view::npos) return std::nullopt;  // by us, or by the user
  // On request only: with "always" the kernel gives them unasked, with "never" not at all.
  if (in.thp_modes.find("[madvise]") == std::string::npos) return std::nullopt;
  std::string out(current);
  if (!out.empty()) out += ':';
  return out + "glibc.malloc.hugetlb=1";
}

void restart_with_huge_pages(int argc, char** argv) {
  HugePageInputs in;
  if (argc >= 2) in.command = argv[1];
  in.opt_out = std::getenv("LAMINA_HUGE_PAGES");
  in.tunables = std::getenv("GLIBC_TUNABLES");
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
  in.sanitized = true;
#endif
  if (in.sanitized || argc < 2) return;
  std::ifstream modes("/sys/kernel/mm/transparent_hugepage/enabled");
  std::getline(modes, in.thp_modes);
  const auto tunables = huge_page_tunables(in);
  if (!tunables) return;
  const std::string before = in.tunables ? in.tunables : "";
  const bool had = in.tunables != nullptr;
  if (::setenv("GLIBC_TUNABLES", tunables->c_str(), 1) != 0) return;
  // The program's own path, not /proc/self/exe: the process is named after the file it runs
  // (ps and top would say "exe").
  const auto self = own_program_path();
  ::execv(self ? self->c_str() : "/proc/self/exe", argv);
  // The restart failed: run as we are, and leave the environment as it was.
  if (had) ::setenv("GLIBC_TUNABLES", before.c_str(), 1); else ::unsetenv("GLIBC_TUNABLES");
}

}  // namespace lamina::cli
