// When `lamina` starts itself again with glibc's huge-page tunable (daemon/cli/huge_pages.cpp):
// only for the commands that read a model, only where the kernel gives huge pages on request,
// never twice, never against the user's own tunables or LAMINA_HUGE_PAGES=0, and keeping the
// tunables the user set.
#include "huge_pages.hpp"

#include <gtest/gtest.h>

namespace lamina_cli_test {
namespace {

using lamina::cli::huge_page_tunables;
using lamina::cli::HugePageInputs;

HugePageInputs plan_on_madvise() {
  HugePageInputs in;
  in.command = "plan";
  in.thp_modes = "always [madvise] never";
  return in;
}

TEST(HugePages, APlanStartsAgainWithTheTunable) {
  EXPECT_EQ(huge_page_tunables(plan_on_madvise()), "glibc.malloc.hugetlb=1");
  for (const char* command : {"check", "slice"}) {
    HugePageInputs in = plan_on_madvise();
    in.command = command;
    EXPECT_EQ(huge_page_tunables(in), "glibc.malloc.hugetlb=1") << command;
  }
}

TEST(HugePages, TheUsersOwnTunablesAreKept) {
  HugePageInputs in = plan_on_madvise();
  in.tunables = "glibc.malloc.arena_max=2";
  EXPECT_EQ(huge_page_tunables(in), "glibc.malloc.arena_max=2:glibc.malloc.hugetlb=1");
}

TEST(HugePages, NeverTwiceNorWhereItIsNotWanted) {
  HugePageInputs in = plan_on_madvise();
  in.tunables = "glibc.malloc.hugetlb=1";  // the restarted process
  EXPECT_EQ(huge_page_tunables(in), std::nullopt);
  in = plan_on_madvise();
  in.tunables = "glibc.malloc.hugetlb=0";  // the user said no
  EXPECT_EQ(huge_page_tunables(in), std::nullopt);
  in = plan_on_madvise();
  in.opt_out = "0";
  EXPECT_EQ(huge_page_tunables(in), std::nullopt);
  in = plan_on_madvise();
  in.command = "stream";  // the machine link: no model, and a long life
  EXPECT_EQ(huge_page_tunables(in), std::nullopt);
  in = plan_on_madvise();
  in.sanitized = true;
  EXPECT_EQ(huge_page_tunables(in), std::nullopt);
  for (const char* modes : {"[always] madvise never", "always madvise [never]", ""}) {
    in = plan_on_madvise();
    in.thp_modes = modes;
    EXPECT_EQ(huge_page_tunables(in), std::nullopt) << modes;
  }
}

}  // namespace
}  // namespace lamina_cli_test
