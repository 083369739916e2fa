// The job store failing under a running daemon (issue 16, item 6): the state directory fills up
// while a sheet cuts, or the database file is deleted. The cut stops safely, requests that
// would write are refused with -32014, what clients read is what the database holds, and after
// a restart with room on the disk the sheet resumes with every finished contour cut once.
#include <gtest/gtest.h>

#include "daemon_fixture.hpp"
#include "modbus_test_client.hpp"

namespace lamina::daemon::testing {
namespace {

const std::string kStorageModel = std::string(LAMINA_EXAMPLES_DIR) + "/knob.stl";

Json machine_status(RpcClient& c) { return call_ok(c, "machine.status"); }

bool wait_store_failed(RpcClient& c, double wait_s) {
  const auto t0 = std::chrono::steady_clock::now();
  while (seconds_since(t0) < wait_s) {
    if (machine_status(c)["store"]["ok"] == false) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return false;
}

TEST(LaminadStorage, ADiskFullWhileCuttingStopsTheCutAndNothingRunsAheadOfTheDisk) {
  Cell cell({}, 20);
  SmallDisk disk(cell.dir.file("state"), "48m");
  if (!disk.mounted()) GTEST_SKIP() << "cannot mount a tmpfs here (" << disk.why() << ")";
  auto daemon = std::make_unique<Laminad>(cell.config(), cell.dir.file(""));
  RpcClient c = connect(cell.socket());
  const std::string id = start_cutting(c, cell, 60);
  Json job;

  ASSERT_GT(disk.fill("fill"), 0u);
  ASSERT_TRUE(wait_store_failed(c, 30)) << "the failed progress save is noticed\n" << daemon->log();
  const Json status = machine_status(c);
  EXPECT_NE(status["store"]["error"].get<std::string>().find("full"), std::string::npos) << status.dump();
  // The cut stops, the jet with it (the PLC's own reading), and nothing moves on.
  ASSERT_TRUE(sim::testing::wait_status(cell.sim.control_port(), [](const Json& s) { return s["state"] != "run"; }, 30));
  drivers::testing::PlcProbe plc(cell.sim.modbus_port());
  EXPECT_EQ(plc.input(drivers::testing::map::kInputJetIsOn), 0);
  const auto stopped_at = executed(cell.log()).size();
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  EXPECT_EQ(executed(cell.log()).size(), stopped_at);

  // Requests that would write are refused, with the code and the way out.
  for (const auto& [method, params] : std::vector<std::pair<std::string, Json>>{
           {"job.resume", {{"job", id}}}, {"job.submit", {{"model", kStorageModel}}}, {"job.cancel", {{"job", id}}}}) {
    auto r = c.call(method, params);
    ASSERT_FALSE(r) << method;
    EXPECT_EQ(r.error().code, -32014) << method;
    EXPECT_NE(r.error().message.find("restart laminad"), std::string::npos) << r.error().message;
  }
  // What a client reads is what the database holds: the state it could not write is not shown.
  const std::string told = call_ok(c, "job.get", {{"job", id}})["state"];

  daemon->stop(SIGTERM);
  std::filesystem::remove(cell.dir.file("state/fill"));
  daemon->start();
  c = connect(cell.socket());
  job = call_ok(c, "job.get", {{"job", id}});
  EXPECT_TRUE(told == "cutting" || told == "paused") << told;
  ASSERT_EQ(job["state"], "interrupted") << job.dump(2) << daemon->log();
  const auto ran_before = executed(cell.log());
  call_ok(c, "job.resume", {{"job", id}});
  job = wait_job(c, id, [](const Json& j) { return j["state"] == "completed" || j["state"] == "paused"; }, 300);
  ASSERT_EQ(job["state"], "completed") << job.dump(2) << daemon->log();
  expect_resumed_at_the_cut_short_contour(program_lines(job["sheets"][0]["program"]), ran_before, executed(cell.log()));
}

// A database deleted under the running daemon used to go unnoticed: SQLite wrote on into the
// unlinked file, and a restart found none of it.
TEST(LaminadStorage, ADeletedDatabaseIsNoticedAndRefused) {
  Cell cell;
  Laminad daemon(cell.config(), cell.dir.file(""));
  RpcClient c = connect(cell.socket());
  EXPECT_EQ(machine_status(c)["store"]["ok"], true);
  std::filesystem::remove(cell.dir.file("state/lamina.db"));
  ASSERT_TRUE(wait_store_failed(c, 5));
  EXPECT_NE(machine_status(c)["store"]["error"].get<std::string>().find("deleted"), std::string::npos);
  auto r = c.call("job.submit", {{"model", kStorageModel}});
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, -32014);
  EXPECT_TRUE(call_ok(c, "job.list").empty());
}

}  // namespace
}  // namespace lamina::daemon::testing
