// When `lamina` starts itself again with glibc's allocator tunables (daemon/cli/malloc_tuning.cpp):
// only for the commands that read a model, huge pages only where the kernel gives them on
// request, never twice, never against LAMINA_MALLOC_TUNING=0, and keeping every tunable the user
// set as the user set it.
#include "malloc_tuning.hpp"

#include <gtest/gtest.h>

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

}  // namespace
}  // namespace lamina_cli_test
