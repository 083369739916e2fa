// When `lamina` starts itself again with glibc's allocator tunables (daemon/cli/malloc_tuning.cpp):
// only for the commands that read a model, huge pages only where the kernel gives them on
// request, never twice, never against LAMINA_MALLOC_TUNING=0, and keeping every tunable the user
// set as the user set it.
#include "malloc_tuning.hpp"

#include <gtest/gtest.h>
#include <malloc.h>

#include <cstdio>
#include <cstdlib>
#include <vector>

namespace lamina_cli_test {
namespace {

using lamina::cli::malloc_tunables;
using lamina::cli::MallocTuningInputs;

constexpr const char* kAll =
    "glibc.malloc.hugetlb=1:glibc.malloc.mmap_threshold=1073741824:glibc.malloc.trim_threshold=1073741824";
constexpr const char* kThresholds = "glibc.malloc.mmap_threshold=1073741824:glibc.malloc.trim_threshold=1073741824";

MallocTuningInputs plan_on_madvise() {
  MallocTuningInputs in;
  in.command = "plan";
  in.thp_modes = "always [madvise] never";
  return in;
}

TEST(MallocTuning, APlanStartsAgainWithTheTunables) {
  EXPECT_EQ(malloc_tunables(plan_on_madvise()), kAll);
  for (const char* command : {"check", "slice"}) {
    MallocTuningInputs in = plan_on_madvise();
    in.command = command;
    EXPECT_EQ(malloc_tunables(in), kAll) << command;
  }
}

TEST(MallocTuning, HugePagesOnlyWhereTheKernelGivesThemOnRequest) {
  for (const char* modes : {"[always] madvise never", "always madvise [never]", ""}) {
    MallocTuningInputs in = plan_on_madvise();
    in.thp_modes = modes;
    EXPECT_EQ(malloc_tunables(in), kThresholds) << modes;
  }
}

TEST(MallocTuning, TheUsersOwnTunablesAreKept) {
  MallocTuningInputs in = plan_on_madvise();
  in.tunables = "glibc.malloc.arena_max=2";
  EXPECT_EQ(malloc_tunables(in), std::string("glibc.malloc.arena_max=2:") + kAll);
  in.tunables = "glibc.malloc.hugetlb=0";  // the user said no to huge pages, not to the rest
  EXPECT_EQ(malloc_tunables(in), std::string("glibc.malloc.hugetlb=0:") + kThresholds);
  in.tunables = "glibc.malloc.trim_threshold=0:glibc.malloc.mmap_threshold=65536";
  EXPECT_EQ(malloc_tunables(in), std::string(in.tunables) + ":glibc.malloc.hugetlb=1");
  // A name that only ends like ours is not ours.
  in.tunables = "x.glibc.malloc.hugetlb=0";
  EXPECT_EQ(malloc_tunables(in), std::string("x.glibc.malloc.hugetlb=0:") + kAll);
}

TEST(MallocTuning, NeverTwiceNorWhereItIsNotWanted) {
  MallocTuningInputs in = plan_on_madvise();
  in.tunables = kAll;  // the restarted process
  EXPECT_EQ(malloc_tunables(in), std::nullopt);
  in = plan_on_madvise();
  in.thp_modes = "[always] madvise never";
  in.tunables = kThresholds;  // restarted where huge pages come unasked
  EXPECT_EQ(malloc_tunables(in), std::nullopt);
  in = plan_on_madvise();
  in.opt_out = "0";
  EXPECT_EQ(malloc_tunables(in), std::nullopt);
  in = plan_on_madvise();
  in.command = "stream";  // the machine link: no model, and a long life
  EXPECT_EQ(malloc_tunables(in), std::nullopt);
  in = plan_on_madvise();
  in.sanitized = true;
  EXPECT_EQ(malloc_tunables(in), std::nullopt);
}

// The pages go back only between the phases that free much and those that need new blocks, not
// before the layering (nothing to gain there: what the mesh's build freed it reuses).
TEST(MallocTuning, FreedPagesGoBackBeforeThePhasesAfterTheLayering) {
  using lamina::PlanPhase;
  using lamina::cli::gives_back_freed_pages_before;
  EXPECT_FALSE(gives_back_freed_pages_before(PlanPhase::checking));
  EXPECT_FALSE(gives_back_freed_pages_before(PlanPhase::choosing_layers));
  EXPECT_FALSE(gives_back_freed_pages_before(PlanPhase::planning_bevels));
  EXPECT_TRUE(gives_back_freed_pages_before(PlanPhase::nesting_and_programs));
  EXPECT_TRUE(gives_back_freed_pages_before(PlanPhase::measuring_deviation));
  EXPECT_TRUE(gives_back_freed_pages_before(PlanPhase::writing_stack));
}

long resident_bytes() {
  long pages = 0, resident = 0;
  if (FILE* f = std::fopen("/proc/self/statm", "r")) {
    if (std::fscanf(f, "%ld %ld", &pages, &resident) != 2) resident = 0;
    std::fclose(f);
  }
  return resident * 4096;
}

// With the plan's thresholds, freed blocks inside the heap stay resident until they are given
// back; after give_back_freed_pages they are not.
TEST(MallocTuning, FreedPagesInsideTheHeapLeaveTheProcess) {
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__) || !defined(__GLIBC__)
  GTEST_SKIP() << "the sanitizer's allocator is its own";
#else
  ASSERT_EQ(mallopt(M_MMAP_THRESHOLD, 32 << 20), 1);  // 64 KiB blocks from the heap, as in a plan
  ASSERT_EQ(mallopt(M_TRIM_THRESHOLD, 1 << 30), 1);
  constexpr std::size_t kBlocks = 1024, kBlock = 64 << 10;  // 64 MiB
  std::vector<char*> blocks;
  for (std::size_t i = 0; i < kBlocks; ++i) {
    blocks.push_back(static_cast<char*>(std::malloc(kBlock)));
    for (std::size_t k = 0; k < kBlock; k += 4096) blocks.back()[k] = 1;  // resident
  }
  char* const last = blocks.back();  // keeps the heap's top in use: only a trim inside it helps
  blocks.pop_back();
  for (char* b : blocks) std::free(b);
  const long before = resident_bytes();
  lamina::cli::give_back_freed_pages();
  const long after = resident_bytes();
  std::free(last);
  mallopt(M_TRIM_THRESHOLD, 128 << 10);
  mallopt(M_MMAP_THRESHOLD, 128 << 10);
  EXPECT_GT(before - after, 48L << 20) << "resident " << before << " → " << after << " bytes";
#endif
}

}  // namespace
}  // namespace lamina_cli_test
