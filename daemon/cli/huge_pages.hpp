#pragma once
// Large blocks on transparent huge pages for the commands that read a model (check, slice, plan).
// On this project's 2-core VMs a 4 KiB page fault costs about 6.6 µs, and reading, welding and
// slicing the 1M-triangle sphere faulted 59 100 times (0.39 s of system time, more than the
// slicing itself); on 2 MiB pages, 8 200 times (docs/performance.md, issue 22). glibc puts its
// large blocks on them when GLIBC_TUNABLES has glibc.malloc.hugetlb=1, which it reads only when a
// program starts: so `lamina` starts itself again once with it set, where the kernel offers
// huge pages on request (THP "madvise"). Not in sanitizer builds (their allocator is their own),
// nor when LAMINA_HUGE_PAGES=0 or the tunable is already set.
#include <optional>
#include <string>
#include <string_view>

namespace lamina::cli {

struct HugePageInputs {
  std::string_view command;             // argv[1]
  const char* opt_out = nullptr;        // $LAMINA_HUGE_PAGES
  const char* tunables = nullptr;       // $GLIBC_TUNABLES
  std::string thp_modes;                // /sys/kernel/mm/transparent_hugepage/enabled
  bool sanitized = false;
};

// The GLIBC_TUNABLES to start again with, or none: stay as we are.
std::optional<std::string> huge_page_tunables(const HugePageInputs& in);

// Returns only when it does not restart (or the restart failed: the command then runs as is).
void restart_with_huge_pages(int argc, char** argv);

}  // namespace lamina::cli
