// Every fault lamina-sim injects stops `lamina stream` in a safe state with a clear reason,
// within a bounded time, and nothing resumes by itself: the jet is off (PLC), the axes stand
// still, and the summary names where an operator may resume.
#include <gtest/gtest.h>

#include <modbus/modbus.h>

#include <cctype>
#include <chrono>
#include <set>
#include <thread>

#include "link_test_support.hpp"

namespace lamina::drivers::testing {
namespace {

struct FaultCase {
  const char* name;
  const char* protocol;
  std::vector<std::string> sim_flags;
  std::set<std::string> reasons;  // acceptable reason codes
  const char* message_has;        // a word the reason's message must carry
  // A lost ok only narrows the window: every line still runs, and the link sees the loss when
  // the controller goes idle with a line unacknowledged.
  bool program_may_finish = false;
  // A fault given through the control socket once the jet is on (the CLI streams meanwhile):
  // one timed from the simulator's start (--estop-at) came before the cut had started on a
  // loaded machine (the CI's sanitizer pass: "line 1 refused", a prepare that failed).
  std::string control_while_cutting;
};

void PrintTo(const FaultCase& c, std::ostream* os) { *os << c.name; }

class LinkFault : public ::testing::TestWithParam<FaultCase> {};

int plc_bit(int port, int address) {
  modbus_t* ctx = modbus_new_tcp("127.0.0.1", port);
  uint8_t bit = 0xFF;
  if (modbus_connect(ctx) == 0) modbus_read_input_bits(ctx, address, 1, &bit);
  modbus_close(ctx);
  modbus_free(ctx);
  return bit;
}

TEST_P(LinkFault, StopsSafelyWithAReasonAndDoesNotResume) {
  const FaultCase& c = GetParam();
  TempDir dir;
  const auto program = contour_program(4, 150);
  const std::string protocol = c.protocol;
  std::vector<std::string> args{"--link", dir.file("cnc"), "--log", dir.file("exec.jsonl"), "--modbus", "127.0.0.1:0",
                                "--control", "127.0.0.1:0", "--pressure-ramp", "0.2", "--time-scale", "2"};
  if (protocol == "xonxoff")
    args.insert(args.end(), {"--personality", "xonxoff", "--rx-buffer", "256", "--planner-blocks", "8"});
  args.insert(args.end(), c.sim_flags.begin(), c.sim_flags.end());
  SimProcess sim(args);
  const auto t0 = std::chrono::steady_clock::now();
  const std::string port = protocol == "modbus" ? "" : fmt::format("--port '{}'", dir.file("cnc"));
  const std::string stream_args = fmt::format("'{}' {} --protocol {} --modbus 127.0.0.1:{}",
                                             write_program(dir, program), port, protocol, sim.modbus_port());
  CliRun run;
  if (c.control_while_cutting.empty()) {
    run = run_lamina_stream(stream_args);
  } else {
    BackgroundStream background(dir, stream_args);
    ASSERT_TRUE(sim::testing::wait_status(
        sim.control_port(), [](const nlohmann::json& s) { return s.value("jet_commanded", false); }, 30));
    ASSERT_EQ(sim::testing::control(sim.control_port(), c.control_while_cutting), "ok");
    run = background.finish();
  }
  const double took_s = sim::testing::seconds_since(t0);
  EXPECT_EQ(run.exit_code, 1) << run.output;
  ASSERT_EQ(run.summary["state"], "stopped") << run.output;
  const std::string code = run.summary["reason"]["code"];
  const std::string message = run.summary["reason"]["message"];
  EXPECT_TRUE(c.reasons.count(code)) << "reason " << code << ": " << message;
  std::string lower = message;
  for (auto& ch : lower) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
  EXPECT_NE(lower.find(c.message_has), std::string::npos) << message;
  EXPECT_TRUE(run.summary.contains("resume")) << "a stopped cut names its resume point: " << run.output;
  EXPECT_LT(took_s, 30) << "bounded";
  // Safe: jet off through the PLC, and the axes stand still from now on.
  EXPECT_EQ(plc_bit(sim.modbus_port(), 3), 0) << "jet_is_on";
  const auto before = executed_lines(dir.file("exec.jsonl"), false).size();
  const auto a = sim::testing::control_status(sim.control_port());
  std::this_thread::sleep_for(std::chrono::milliseconds(700));
  const auto b = sim::testing::control_status(sim.control_port());
  EXPECT_EQ(a["position"], b["position"]) << "the machine moved after the stop";
  EXPECT_EQ(executed_lines(dir.file("exec.jsonl"), false).size(), before) << "nothing ran after the stop";
  if (!c.program_may_finish) {
    EXPECT_LT(executed_lines(dir.file("exec.jsonl")).size(), program.size());
  }
}

INSTANTIATE_TEST_SUITE_P(
    EveryInjectedFault, LinkFault,
    ::testing::Values(
        FaultCase{"garbled_bytes", "grbl", {"--garble", "0.003", "--seed", "3"}, {"controller_error", "protocol_error", "timeout", "controller_alarm"}, "", false, ""},
        FaultCase{"lost_ok", "grbl", {"--drop-ok", "120"}, {"protocol_error"}, "acknowledgement lost", true, ""},
        FaultCase{"unplugged", "grbl", {"--unplug-at-line", "200"}, {"io_error"}, "cnc", false, ""},
        FaultCase{"alarm", "grbl", {"--alarm-at-line", "150"}, {"controller_alarm"}, "alarm 1", false, ""},
        FaultCase{"estop", "grbl", {}, {"interlock", "controller_alarm"}, "stop", false, "estop on"},
        FaultCase{"pressure_drop", "grbl", {}, {"interlock"}, "pressure", false, "pressure drop"},
        FaultCase{"stall", "grbl", {}, {"timeout"}, "stalled", false, "stall 15000"}),
    [](const ::testing::TestParamInfo<FaultCase>& info) { return std::string(info.param.name); });

// The other protocols, on the faults their paths differ in: the controller's own alarm, the
// cell's interlocks (for a drip feed the PLC's feed-hold button is the only hold), a lost link.
INSTANTIATE_TEST_SUITE_P(
    OtherProtocols, LinkFault,
    ::testing::Values(
        FaultCase{"send_response_alarm", "send-response", {"--alarm-at-line", "150"}, {"controller_alarm"}, "alarm 1", false, ""},
        FaultCase{"send_response_unplugged", "send-response", {"--unplug-at-line", "200"}, {"io_error"}, "cnc", false, ""},
        FaultCase{"xonxoff_alarm", "xonxoff", {"--alarm-at-line", "150"}, {"controller_alarm"}, "nak", false, ""},
        FaultCase{"xonxoff_pressure_drop", "xonxoff", {}, {"interlock"}, "pressure", false, "pressure drop"},
        FaultCase{"xonxoff_estop", "xonxoff", {}, {"interlock", "controller_alarm"}, "stop", false, "estop on"},
        FaultCase{"modbus_alarm", "modbus", {"--alarm-at-line", "150"}, {"controller_alarm"}, "alarm", false, ""},
        FaultCase{"modbus_pressure_drop", "modbus", {}, {"interlock"}, "pressure", false, "pressure drop"},
        FaultCase{"modbus_estop", "modbus", {}, {"interlock", "controller_alarm"}, "stop", false, "estop on"}),
    [](const ::testing::TestParamInfo<FaultCase>& info) { return std::string(info.param.name); });

}  // namespace
}  // namespace lamina::drivers::testing
