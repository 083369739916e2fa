// laminad's crash safety and shutdown: kill -9 while cutting → restart → the job is interrupted
// with its last acknowledged line → job.resume finishes it with no finished contour cut twice;
// SIGTERM while cutting holds the machine, leaves the jet off and the job interrupted.
#include <gtest/gtest.h>

#include "daemon_fixture.hpp"

namespace lamina::daemon::testing {
namespace {

const std::string kModel = std::string(LAMINA_EXAMPLES_DIR) + "/knob.stl";

std::string start_cutting(RpcClient& c, Cell& cell, std::size_t blocks_before) {
  Json job = call_ok(c, "job.submit", {{"model", kModel}, {"settings", {{"stock", "5"}}}});
  const std::string id = job["id"];
  job = wait_state(c, id, "waiting_sheet", 120);
  if (job["state"] != "waiting_sheet") throw std::runtime_error("not planned: " + job.dump());
  call_ok(c, "job.confirm_sheet", {{"job", id}, {"sheet", 1}});
  if (!sim::testing::wait_status(cell.sim.control_port(),
                                 [&](const Json& s) { return s["executed_blocks"].get<std::size_t>() > blocks_before; }, 60))
    throw std::runtime_error("the cut did not start");
  return id;
}

TEST(LaminadRecovery, KilledWhileCuttingComesBackInterruptedAndResumesOnRequest) {
  Cell cell({}, 40);
  auto daemon = std::make_unique<Laminad>(cell.config(), cell.dir.file(""));
  std::string id;
  {
    RpcClient c = connect(cell.socket());
    id = start_cutting(c, cell, 400);
    std::this_thread::sleep_for(std::chrono::milliseconds(600));  // some progress saved
  }
  EXPECT_EQ(daemon->stop(SIGKILL), -SIGKILL);
  // Without its heartbeat the PLC closes the jet; the CNC finishes what it had queued.
  ASSERT_TRUE(sim::testing::wait_status(cell.sim.control_port(),
                                        [](const Json& s) { return s["queued_blocks"] == 0 && s["state"] != "run"; }, 30));
  const auto ran_before = executed(cell.log());

  daemon->start();
  RpcClient c = connect(cell.socket());
  Json job = call_ok(c, "job.get", {{"job", id}});
  ASSERT_EQ(job["state"], "interrupted") << job.dump(2) << daemon->log();
  const std::size_t acked = job["sheets"][0]["last_acked_line"];
  EXPECT_GT(acked, 0u);
  EXPECT_LE(acked, job["sheets"][0]["lines"].get<std::size_t>());
  EXPECT_NE(job["error"].get<std::string>().find("stopped while"), std::string::npos) << job["error"];
  // It waits for the operator.
  std::this_thread::sleep_for(std::chrono::milliseconds(700));
  EXPECT_EQ(executed(cell.log()).size(), ran_before.size());
  EXPECT_EQ(call_ok(c, "job.get", {{"job", id}})["state"], "interrupted");

  call_ok(c, "job.resume", {{"job", id}});
  job = wait_job(c, id, [](const Json& j) { return j["state"] == "completed" || j["state"] == "paused" || j["state"] == "failed"; }, 300);
  ASSERT_EQ(job["state"], "completed") << job.dump(2) << daemon->log();

  // The first run is the program's prefix; the resumed run starts at the contour that was being
  // cut when the daemon died: no finished contour runs twice, nothing is skipped.
  const auto lines = program_lines(job["sheets"][0]["program"]);
  const auto log = executed(cell.log());
  std::size_t done = 0;
  while (done < ran_before.size() && ran_before[done].line == lines[done]) ++done;
  ASSERT_EQ(done, ran_before.size()) << "the first run is the program in order";
  std::size_t finished = 0;  // lines that completed in the first run
  for (std::size_t i = 0; i < ran_before.size(); ++i)
    if (ran_before[i].completed) finished = i + 1;
  std::size_t contour_start = 0;
  for (std::size_t k = 0; k <= std::min(finished, lines.size() - 1); ++k)
    if (lines[k].rfind("(CONTOUR ", 0) == 0) contour_start = k;
  std::size_t resumed_at = log.size();
  for (std::size_t i = ran_before.size(); i < log.size(); ++i)
    if (log[i].line == lines[contour_start]) {
      resumed_at = i;
      break;
    }
  ASSERT_LT(resumed_at, log.size()) << "the resumed run starts at contour line " << contour_start + 1;
  ASSERT_EQ(log.size() - resumed_at, lines.size() - contour_start);
  for (std::size_t i = 0; i < lines.size() - contour_start; ++i)
    ASSERT_EQ(log[resumed_at + i].line, lines[contour_start + i]) << "resumed block " << i + 1;
}

TEST(LaminadRecovery, SigtermWhileCuttingLeavesTheCellSafeAndTheJobInterrupted) {
  Cell cell({}, 40);
  Laminad daemon(cell.config(), cell.dir.file(""));
  std::string id;
  {
    RpcClient c = connect(cell.socket());
    id = start_cutting(c, cell, 200);
  }
  EXPECT_EQ(daemon.stop(SIGTERM), 0) << daemon.log();
  const Json st = sim::testing::control_status(cell.sim.control_port());
  EXPECT_NE(st["state"], "run") << "the machine is held or idle";
  const auto a = executed(cell.log()).size();
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  EXPECT_EQ(executed(cell.log()).size(), a) << "nothing moves after the daemon stopped";

  daemon.start();
  RpcClient c = connect(cell.socket());
  const Json job = call_ok(c, "job.get", {{"job", id}});
  EXPECT_EQ(job["state"], "interrupted") << job.dump(2);
  EXPECT_EQ(call_ok(c, "machine.status")["cell"]["jet_is_on"], false);
}

}  // namespace
}  // namespace lamina::daemon::testing
