// run_plan_process with a stand-in planner (a shell script in the place of `lamina`): the phase
// lines it writes on its progress descriptor reach the callback in order, whole, garbage
// skipped; its report is returned; a failing planner's error lines become the message.
#include <gtest/gtest.h>

#include <sys/stat.h>

#include <atomic>
#include <fstream>
#include <vector>

#include "plan_process.hpp"
#include "sim_process.hpp"

namespace lamina::daemon {
namespace {

using sim::testing::TempDir;

std::string write_script(const TempDir& dir, const std::string& body) {
  const std::string path = dir.file("fake-lamina");
  std::ofstream(path) << "#!/bin/sh\n" << body;
  ::chmod(path.c_str(), 0755);
  return path;
}

PlanProcessRequest request_for(const TempDir& dir, const std::string& planner) {
  PlanProcessRequest r;
  r.lamina = planner;
  r.model = dir.file("model.stl");
  r.out_dir = dir.file("out");
  r.timeout_s = 30;
  return r;
}

// Arguments as laminad passes them: plan MODEL --out DIR --json --progress-fd N …
TEST(PlanProcess, PhaseLinesReachTheCallbackInOrderAndWhole) {
  TempDir dir;
  const std::string planner = write_script(dir, R"(
[ "$1" = plan ] && [ "$3" = --out ] && [ "$6" = --progress-fd ] || { echo "error: arguments $*"; exit 2; }
fd=$7
eval "exec 9>&$fd"
echo '{"phase":"choosing layers","step":1,"steps":2}' >&9
printf '{"phase":"planning ' >&9
sleep 0.2
echo 'bevels","step":2,"steps":2}' >&9
echo 'not a phase' >&9
echo '{"sheets":[],"layers":[1,2,3]}' > "$4/report.json"
)");
  std::atomic<bool> cancel{false};
  std::vector<nlohmann::json> seen;
  auto report = run_plan_process(request_for(dir, planner), cancel, [&](const nlohmann::json& p) { seen.push_back(p); });
  ASSERT_TRUE(report) << report.error().message;
  EXPECT_EQ((*report)["layers"].size(), 3u);
  ASSERT_EQ(seen.size(), 2u);
  EXPECT_EQ(seen[0]["phase"], "choosing layers");
  EXPECT_EQ(seen[1]["phase"], "planning bevels") << "a line split across writes arrives whole";
  EXPECT_EQ(seen[1]["step"], 2);
}

TEST(PlanProcess, AFailedPlannerGivesItsErrorLinesAndNoReport) {
  TempDir dir;
  const std::string planner = write_script(dir, "echo 'reading the model'\necho 'error [invalid_argument]: model.stl is not usable'\nexit 1\n");
  std::atomic<bool> cancel{false};
  auto report = run_plan_process(request_for(dir, planner), cancel);
  ASSERT_FALSE(report);
  EXPECT_FALSE(report.error().cancelled);
  EXPECT_NE(report.error().message.find("model.stl is not usable"), std::string::npos) << report.error().message;
}

TEST(PlanProcess, APlannerThatIgnoresItsProgressPipeStillPlans) {
  TempDir dir;
  const std::string planner = write_script(dir, "echo '{}' > \"$4/report.json\"\n");
  std::atomic<bool> cancel{false};
  int calls = 0;
  auto report = run_plan_process(request_for(dir, planner), cancel, [&](const nlohmann::json&) { ++calls; });
  ASSERT_TRUE(report) << report.error().message;
  EXPECT_EQ(calls, 0);
}

}  // namespace
}  // namespace lamina::daemon

namespace lamina::daemon {
namespace {

// Issue 16, item 11: `stock_file=/dev/zero` grew a planner to 1.8 GB in 6 s beside a cut. The
// child runs under its limits (address space, CPU time, nice) and is the OOM killer's first pick.
TEST(PlanProcess, ThePlannerRunsUnderItsLimits) {
  TempDir dir;
  const std::string planner = write_script(dir, R"(
echo "{\"as_kb\": \"$(ulimit -v)\", \"cpu_s\": \"$(ulimit -t)\", \"nice\": $(nice), \"oom\": $(cat /proc/self/oom_score_adj)}" > "$4/report.json"
)");
  PlanProcessRequest r = request_for(dir, planner);
  r.limits = {512ull << 20, 100, 7};
  std::atomic<bool> cancel{false};
  auto report = run_plan_process(r, cancel);
  ASSERT_TRUE(report) << report.error().message;
  EXPECT_EQ((*report)["as_kb"], "524288");
  EXPECT_EQ((*report)["cpu_s"], "100");
  EXPECT_EQ((*report)["nice"], 7);
  EXPECT_EQ((*report)["oom"], 1000);
}

TEST(PlanProcess, APlannerOverItsCpuTimeIsStoppedAndTheMessageSaysWhy) {
  TempDir dir;
  const std::string planner = write_script(dir, "while :; do :; done\n");
  PlanProcessRequest r = request_for(dir, planner);
  r.limits.cpu_s = 1;
  std::atomic<bool> cancel{false};
  auto report = run_plan_process(r, cancel);
  ASSERT_FALSE(report);
  EXPECT_NE(report.error().message.find("CPU-time limit is 1 s"), std::string::npos) << report.error().message;
}

}  // namespace
}  // namespace lamina::daemon
