// run_plan_process with a stand-in planner (a shell script in the place of `lamina`): the phase
// lines it writes on its progress descriptor reach the callback in order, whole, garbage
// skipped; its report is returned, read with the planner's schema (a report that does not match
// fails loudly); a failing planner's error lines become the message.
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

// A report as `lamina plan` writes it (the same serialisation), with `layers` layers.
std::string valid_report(const TempDir& dir, int layers) {
  PlanReport report;
  report.layers.resize(static_cast<std::size_t>(layers));
  report.deviation.emplace_back("curved", ReportDeviation{});
  const std::string path = dir.file("valid-report.json");
  std::ofstream(path) << plan_report_json(report);
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
cp "$9" "$4/report.json"
)");
  std::atomic<bool> cancel{false};
  std::vector<nlohmann::json> seen;
  PlanProcessRequest request = request_for(dir, planner);
  request.flags = {valid_report(dir, 3)};  // $9: the stand-in copies it
  auto report = run_plan_process(request, cancel, [&](const nlohmann::json& p) { seen.push_back(p); });
  ASSERT_TRUE(report) << report.error().message;
  EXPECT_EQ(report->layers.size(), 3u);
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
  const std::string planner = write_script(dir, "cp \"$9\" \"$4/report.json\"\n");
  PlanProcessRequest request = request_for(dir, planner);
  request.flags = {valid_report(dir, 1)};
  std::atomic<bool> cancel{false};
  int calls = 0;
  auto report = run_plan_process(request, cancel, [&](const nlohmann::json&) { ++calls; });
  ASSERT_TRUE(report) << report.error().message;
  EXPECT_EQ(calls, 0);
}

// Issue 18: laminad read report.json with value(key, default), so a renamed field became sheet 0
// or an empty path without a word. A report that does not match the schema fails the plan, and
// the message names the key.
TEST(PlanProcess, AReportThatDoesNotMatchTheSchemaIsRefusedNamingTheKey) {
  TempDir dir;
  const std::string good = valid_report(dir, 2);
  std::ifstream in(good);
  std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  const std::string renamed = dir.file("renamed.json");
  const auto at = text.find("\"shortfalls\"");
  ASSERT_NE(at, std::string::npos);
  std::ofstream(renamed) << text.replace(at, 12, "\"short_falls\"");
  const std::string planner = write_script(dir, "cp \"$9\" \"$4/report.json\"\n");
  PlanProcessRequest request = request_for(dir, planner);
  request.flags = {renamed};
  std::atomic<bool> cancel{false};
  auto report = run_plan_process(request, cancel);
  ASSERT_FALSE(report);
  EXPECT_NE(report.error().message.find("shortfalls: missing"), std::string::npos) << report.error().message;
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
echo "{\"as_kb\": \"$(ulimit -v)\", \"cpu_s\": \"$(ulimit -t)\", \"nice\": $(nice), \"oom\": $(cat /proc/self/oom_score_adj)}" > "$4/../limits.json"
cp "$9" "$4/report.json"
)");
  PlanProcessRequest r = request_for(dir, planner);
  r.flags = {valid_report(dir, 1)};
  r.limits = {512ull << 20, 100, 7};
  std::atomic<bool> cancel{false};
  auto report = run_plan_process(r, cancel);
  ASSERT_TRUE(report) << report.error().message;
  const auto limits = nlohmann::json::parse(std::ifstream(dir.file("limits.json")));
  EXPECT_EQ(limits["as_kb"], "524288");
  EXPECT_EQ(limits["cpu_s"], "100");
  EXPECT_EQ(limits["nice"], 7);
  EXPECT_EQ(limits["oom"], 1000);
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
