#pragma once
// The allocator's settings for the commands that read a model (check, slice, plan), set by
// starting `lamina` once more with GLIBC_TUNABLES (glibc reads them only when a program starts;
// mallopt cannot raise the mmap threshold past 32 MiB). On this project's 2-core VMs a 4 KiB page
// fault costs about 6.6 µs (docs/performance.md, issue 22):
//  - glibc.malloc.hugetlb=1 puts large blocks on transparent huge pages, where the kernel gives
//    them on request (THP "madvise"): reading, welding and slicing the 1M-triangle sphere faulted
//    59 100 times on 4 KiB pages, 8 200 times on 2 MiB ones;
//  - glibc.malloc.mmap_threshold and trim_threshold at 1 GiB keep freed blocks in the heap for
//    the next one: by default every block above a few MiB is a fresh mmap that faults again
//    (each topology pass's tables, each layer's buffers); on the sphere's slice 15 000 → 4 500
//    faults. A plan is a short process: what it frees and keeps is returned when it ends.
// Not in sanitizer builds (their allocator is their own), nor when LAMINA_MALLOC_TUNING=0; a
// tunable the user set is kept as the user set it.
#include "lamina/core/plan_job.hpp"

#include <optional>
#include <string>
#include <string_view>

namespace lamina::cli {

struct MallocTuningInputs {
  std::string_view command;             // argv[1]
  const char* opt_out = nullptr;        // $LAMINA_MALLOC_TUNING
  const char* tunables = nullptr;       // $GLIBC_TUNABLES
  std::string thp_modes;                // /sys/kernel/mm/transparent_hugepage/enabled
  bool sanitized = false;
};

// The GLIBC_TUNABLES to start again with, or none: stay as we are (nothing to add).
std::optional<std::string> malloc_tunables(const MallocTuningInputs& in);

// Returns only when it does not restart (or the restart failed: the command then runs as is).
void restart_with_malloc_tuning(int argc, char** argv);

// With those thresholds the heap keeps every page it frees, and a plan's phases free much: the
// layering's sub-slices and verification plans (~100 MB of the 1M sphere) are free when the
// nesting starts, but the toolpaths, the deviation's trees and the stack's bytes do not fit the
// holes they left, so each phase grew the process anew (peak RSS 357 MiB). Before each phase that
// follows the layering the free pages go back to the kernel (malloc_trim): 322 MiB, no slower
// within the noise (docs/performance.md, issue 22, eleventh session). Not before the layering:
// what the mesh's build freed is reused by it (no gain measured, more page faults). Only when at
// least 32 MiB is free: a small plan's few pages are not worth faulting in again.
bool gives_back_freed_pages_before(PlanPhase phase);
void give_back_freed_pages();

}  // namespace lamina::cli
