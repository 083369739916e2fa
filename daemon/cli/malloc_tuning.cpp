#include "malloc_tuning.hpp"

#include "own_path.hpp"

#include <malloc.h>
#include <unistd.h>

#include <cstdlib>
#include <fstream>

namespace lamina::cli {

namespace {

struct Tunable {
  std::string_view name;
  std::string_view value;
  bool on_request_thp_only;  // only where the kernel gives huge pages on request
};

// Blocks up to 1 GiB come from the heap and stay there when freed (the header says why).
constexpr Tunable kTunables[] = {
    {"glibc.malloc.hugetlb", "1", true},
    {"glibc.malloc.mmap_threshold", "1073741824", false},
    {"glibc.malloc.trim_threshold", "1073741824", false},
};

bool names(std::string_view tunables, std::string_view name) {
  for (std::size_t at = tunables.find(name); at != std::string_view::npos; at = tunables.find(name, at + 1)) {
    const bool starts = at == 0 || tunables[at - 1] == ':';
    const std::size_t end = at + name.size();
    if (starts && end < tunables.size() && tunables[end] == '=') return true;
  }
  return false;
}

}  // namespace

std::optional<std::string> malloc_tunables(const MallocTuningInputs& in) {
  if (in.sanitized) return std::nullopt;
  if (in.command != "check" && in.command != "slice" && in.command != "plan") return std::nullopt;
  if (in.opt_out && std::string_view(in.opt_out) == "0") return std::nullopt;
  const std::string_view current = in.tunables ? in.tunables : "";
  // "always": the kernel gives them unasked; "never": not at all.
  const bool on_request = in.thp_modes.find("[madvise]") != std::string::npos;
  std::string out(current);
  bool added = false;
  for (const Tunable& t : kTunables) {
    if (names(current, t.name) || (t.on_request_thp_only && !on_request)) continue;  // by us, or by the user
    if (!out.empty()) out += ':';
    out.append(t.name).append("=").append(t.value);
    added = true;
  }
  if (!added) return std::nullopt;  // the restarted process, or nothing we would change
  return out;
}

void restart_with_malloc_tuning(int argc, char** argv) {
  MallocTuningInputs in;
  if (argc >= 2) in.command = argv[1];
  in.opt_out = std::getenv("LAMINA_MALLOC_TUNING");
  in.tunables = std::getenv("GLIBC_TUNABLES");
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
  in.sanitized = true;
#endif
  if (in.sanitized || argc < 2) return;
  std::ifstream modes("/sys/kernel/mm/transparent_hugepage/enabled");
  std::getline(modes, in.thp_modes);
  const auto tunables = malloc_tunables(in);
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

bool gives_back_freed_pages_before(PlanPhase phase) {
  switch (phase) {
    case PlanPhase::nesting_and_programs:
    case PlanPhase::measuring_deviation:
    case PlanPhase::writing_stack: return true;
    case PlanPhase::checking:
    case PlanPhase::choosing_layers:
    case PlanPhase::planning_bevels: return false;
  }
  return false;
}

void give_back_freed_pages() {
#if defined(__GLIBC__)
  // A small plan's few free pages are not worth faulting in again (the knob: 3 200 → 7 900
  // faults, 0.83 → 0.87 s, for 2 MiB).
  constexpr std::size_t kWorthGivingBack = 32u << 20;
  if (::mallinfo2().fordblks >= kWorthGivingBack) ::malloc_trim(0);
#endif
}

}  // namespace lamina::cli
