// Lines a controller answers only when done, and the stops the host decides on its own.
//
// grblHAL answers a dwell only after it (standing Idle meanwhile), and a jet M-code or program
// end only once the motion before it is done: `lamina stream` must take that for work, not for
// a stall (it stopped every Lamina program at its first pierce dwell on the real firmware).
// And a stop the host decides — a stall, a lost ack, a refused line, the operator's abort, a
// controller found held — must never leave the jet on. These run without a PLC, where the
// controller's own M-code is the only jet output: the link's soft reset must turn it off.
// Simulated time runs at 1: a dwell lasts what the program says, as on the machine.
#include <gtest/gtest.h>

#include <signal.h>

#include <chrono>
#include <thread>

#include "link_test_support.hpp"
#include "modbus_test_client.hpp"

namespace lamina::drivers::testing {
namespace {

using sim::testing::StreamClient;

// A pierce as our posts write it (jet on, dwell), then `moves` 0.5 mm cuts, jet off, end.
std::vector<std::string> pierce_program(const std::string& dwell, int moves, double feed_mm_per_min = 600) {
  std::vector<std::string> p{"G21G90G94G17", "G0X10Y10Z10A0C0", "(CONTOUR 0 L1-1 OUTLINE 0 PASS 0 FREES)",
                             "G0X20Y20", "Z0", "M3", dwell};
  for (int i = 1; i <= moves; ++i) p.push_back(fmt::format("G1X{:.1f}Y20F{:.0f}", 20 + 0.5 * i, feed_mm_per_min));
  p.insert(p.end(), {"M5", "G0Z10", "M30"});
  return p;
}

std::size_t index_of(const std::vector<std::string>& p, const std::string& line) {
  return static_cast<std::size_t>(std::find(p.begin(), p.end(), line) - p.begin());
}

std::vector<std::string> sim_args(const TempDir& dir, std::vector<std::string> extra = {}) {
  std::vector<std::string> args{"--link", dir.file("cnc"), "--log", dir.file("exec.jsonl"), "--control", "127.0.0.1:0",
                                "--time-scale", "1"};
  args.insert(args.end(), extra.begin(), extra.end());
  return args;
}

// The machine after a stop: the controller's jet output off, the axes still from now on.
void expect_safe(const SimProcess& sim, const TempDir& dir) {
  const auto a = sim::testing::control_status(sim.control_port());
  EXPECT_EQ(a["jet_commanded"], false) << "the jet is still on at the controller: " << a.dump();
  const auto ran = executed_lines(dir.file("exec.jsonl"), false).size();
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  const auto b = sim::testing::control_status(sim.control_port());
  EXPECT_EQ(a["position"], b["position"]) << "the machine moved after the stop";
  EXPECT_EQ(executed_lines(dir.file("exec.jsonl"), false).size(), ran) << "nothing ran after the stop";
}

bool jet_on(const nlohmann::json& status) { return status.value("jet_commanded", false); }

struct SyncCase {
  const char* protocol;
  double status_hz;
};
void PrintTo(const SyncCase& c, std::ostream* os) { *os << c.protocol << "@" << c.status_hz; }
class DwellAfterJetOn : public ::testing::TestWithParam<SyncCase> {};

TEST_P(DwellAfterJetOn, IsWorkNotAStall) {
  const SyncCase& c = GetParam();
  TempDir dir;
  SimProcess sim(sim_args(dir));
  const auto program = pierce_program("G4P2", 20);
  const CliRun run = run_lamina_stream(fmt::format("'{}' --port '{}' --protocol {} --status-hz {}",
                                                   write_program(dir, program), dir.file("cnc"), c.protocol,
                                                   c.status_hz));
  EXPECT_EQ(run.exit_code, 0) << run.output;
  EXPECT_EQ(run.summary["state"], "completed") << run.output;
  EXPECT_EQ(executed_lines(dir.file("exec.jsonl")), program) << "the execution log is the program";
}

INSTANTIATE_TEST_SUITE_P(Protocols, DwellAfterJetOn,
                         ::testing::Values(SyncCase{"grbl", 5}, SyncCase{"grbl", 20}, SyncCase{"send-response", 5},
                                           SyncCase{"send-response", 20}),
                         [](const ::testing::TestParamInfo<SyncCase>& info) {
                           std::string name = info.param.protocol;
                           std::replace(name.begin(), name.end(), '-', '_');
                           return fmt::format("{}_{}hz", name, static_cast<int>(info.param.status_hz));
                         });

// The ok of M3 is lost: during the 4 s dwell after it, the oldest line the host waits on is
// M3, which the controller answered long ago. That is a lost acknowledgement (the program
// cannot be trusted), found within the margin — during the pierce, with the jet on.
TEST(HostStop, LostAckDuringAPierceTurnsTheJetOff) {
  TempDir dir;
  const auto program = pierce_program("G4P4", 20);
  // The simulator counts every ok it sends: the handshake's `$I` is the first.
  const std::size_t m3_ok = 1 + index_of(program, "M3") + 1;
  SimProcess sim(sim_args(dir, {"--drop-ok", std::to_string(m3_ok)}));
  const auto t0 = std::chrono::steady_clock::now();
  const CliRun run = run_lamina_stream(fmt::format("'{}' --port '{}'", write_program(dir, program), dir.file("cnc")));
  EXPECT_EQ(run.summary["state"], "stopped") << run.output;
  EXPECT_EQ(run.summary["reason"]["code"], "protocol_error") << run.output;
  EXPECT_NE(run.summary["reason"]["message"].get<std::string>().find("acknowledgement lost"), std::string::npos);
  EXPECT_LT(sim::testing::seconds_since(t0), 30) << "bounded";
  EXPECT_LT(executed_lines(dir.file("exec.jsonl")).size(), index_of(program, "G4P4") + 1) << "stopped in the dwell";
  expect_safe(sim, dir);
}

// The controller stops reading its buffer (the simulator's stall) while it cuts, jet on:
// stopped within the margin after its queue ran dry, and the jet off.
TEST(HostStop, StalledControllerIsStoppedWithTheJetOff) {
  TempDir dir;
  SimProcess sim(sim_args(dir));
  const auto program = pierce_program("G4P0.1", 400);
  BackgroundStream run_in_background(dir, fmt::format("'{}' --port '{}'", write_program(dir, program), dir.file("cnc")));
  ASSERT_TRUE(sim::testing::wait_status(sim.control_port(), jet_on, 30));
  const auto t0 = std::chrono::steady_clock::now();
  ASSERT_EQ(sim::testing::control(sim.control_port(), "stall 120000"), "ok");
  const CliRun run = run_in_background.finish();
  EXPECT_EQ(run.summary["state"], "stopped") << run.output;
  EXPECT_EQ(run.summary["reason"]["code"], "timeout") << run.output;
  EXPECT_NE(run.summary["reason"]["message"].get<std::string>().find("stalled"), std::string::npos) << run.output;
  EXPECT_LT(sim::testing::seconds_since(t0), 30) << "bounded";
  expect_safe(sim, dir);
}

// error:N on a line after the pierce: grblHAL runs what it had queued and then stands, jet on.
TEST(HostStop, RefusedLineStopsWithTheJetOff) {
  TempDir dir;
  SimProcess sim(sim_args(dir));
  auto program = pierce_program("G4P0.1", 40);
  program.insert(program.begin() + static_cast<std::ptrdiff_t>(index_of(program, "M5")), "G1X1.2.3");
  const CliRun run = run_lamina_stream(fmt::format("'{}' --port '{}'", write_program(dir, program), dir.file("cnc")));
  EXPECT_EQ(run.summary["state"], "stopped") << run.output;
  EXPECT_EQ(run.summary["reason"]["code"], "controller_error") << run.output;
  expect_safe(sim, dir);
}

// The operator's Ctrl-C during the cut.
TEST(HostStop, InterruptTurnsTheJetOff) {
  TempDir dir;
  SimProcess sim(sim_args(dir));
  const auto program = pierce_program("G4P0.1", 2000, 300);  // 100 s of cutting
  BackgroundStream run_in_background(dir, fmt::format("'{}' --port '{}'", write_program(dir, program), dir.file("cnc")));
  ASSERT_TRUE(sim::testing::wait_status(sim.control_port(), jet_on, 30));
  ASSERT_TRUE(run_in_background.signal(SIGINT));
  const CliRun run = run_in_background.finish();
  EXPECT_EQ(run.summary["state"], "stopped") << run.output;
  EXPECT_EQ(run.summary["reason"]["code"], "cancelled") << run.output;
  expect_safe(sim, dir);
}

// With the cell's PLC, Ctrl-C leaves the cell safe too (issue 16, item 4): the program is
// leaving and nobody will resume, so pump and abrasive go off with the jet.
TEST(HostStop, InterruptWithThePlcTurnsPumpAndAbrasiveOff) {
  TempDir dir;
  SimProcess sim(sim_args(dir, {"--modbus", "127.0.0.1:0", "--pressure-ramp", "0.2"}));
  const auto program = pierce_program("G4P0.1", 2000, 300);
  BackgroundStream run_in_background(dir, fmt::format("'{}' --port '{}' --modbus 127.0.0.1:{}", write_program(dir, program),
                                                      dir.file("cnc"), sim.modbus_port()));
  ASSERT_TRUE(sim::testing::wait_status(sim.control_port(), jet_on, 30));
  PlcProbe plc(sim.modbus_port());
  ASSERT_EQ(plc.coil(map::kCoilPump), 1);
  ASSERT_TRUE(run_in_background.signal(SIGINT));
  const CliRun run = run_in_background.finish();
  EXPECT_EQ(run.summary["reason"]["code"], "cancelled") << run.output;
  EXPECT_EQ(plc.coil(map::kCoilJet), 0);
  EXPECT_EQ(plc.coil(map::kCoilAbrasive), 0);
  EXPECT_EQ(plc.coil(map::kCoilPump), 0) << run.output;
}

// An earlier host left the controller in Hold:0 with the jet on. `lamina stream` says so before
// its first line (send-response waited 120 s in silence), and turns the jet off.
class HeldController : public ::testing::TestWithParam<const char*> {};

TEST_P(HeldController, IsReportedBeforeTheFirstLine) {
  TempDir dir;
  SimProcess sim(sim_args(dir, {"--on-open", "quiet"}));
  {
    StreamClient earlier = StreamClient::open_pty(dir.file("cnc"));
    ASSERT_TRUE(earlier.send("G21G90G94\nM3\nG1X300F60\n"));
    ASSERT_TRUE(sim::testing::wait_status(sim.control_port(), jet_on, 10));
    ASSERT_TRUE(earlier.send("!"));
    ASSERT_TRUE(sim::testing::wait_status(
        sim.control_port(), [](const nlohmann::json& s) { return s.value("state", "") == "hold"; }, 10));
  }  // the earlier host is gone; the controller stays held
  const auto t0 = std::chrono::steady_clock::now();
  const CliRun run = run_lamina_stream(fmt::format("'{}' --port '{}' --protocol {}",
                                                   write_program(dir, pierce_program("G4P0.1", 5)), dir.file("cnc"),
                                                   GetParam()));
  EXPECT_EQ(run.summary["reason"]["code"], "controller_held") << run.output;
  EXPECT_NE(run.summary["reason"]["message"].get<std::string>().find("Hold"), std::string::npos) << run.output;
  EXPECT_LT(sim::testing::seconds_since(t0), 20) << "reported, not waited on";
  EXPECT_TRUE(executed_lines(dir.file("exec.jsonl")).size() <= 3u) << "none of our lines ran";
  expect_safe(sim, dir);
}

INSTANTIATE_TEST_SUITE_P(Protocols, HeldController, ::testing::Values("grbl", "send-response"),
                         [](const ::testing::TestParamInfo<const char*>& info) {
                           std::string name = info.param;
                           std::replace(name.begin(), name.end(), '-', '_');
                           return name;
                         });

}  // namespace
}  // namespace lamina::drivers::testing
