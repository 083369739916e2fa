// Every fault lamina-sim injects does what it says, seen from outside the process.
#include <gtest/gtest.h>

#include <modbus/modbus.h>

#include "grbl_client.hpp"
#include "sim_process.hpp"

namespace lamina::sim::testing {
namespace {

struct FaultSim : LoggedSim {
  explicit FaultSim(std::vector<std::string> extra) : LoggedSim(std::move(extra)) {}
  StreamClient connect() {
    StreamClient c = StreamClient::open_pty(link);
    if (!wait_controller(c)) throw std::runtime_error("no status report");
    c.buffer().clear();
    return c;
  }
  std::vector<nlohmann::json> events(const std::string& name) const {
    std::vector<nlohmann::json> out;
    for (const auto& r : read_log(log))
      if (r.value("event", "") == name) out.push_back(r);
    return out;
  }
};

// libmodbus client on the simulator's PLC.
struct PlcClient {
  modbus_t* ctx;
  explicit PlcClient(int port) : ctx(modbus_new_tcp("127.0.0.1", port)) {
    if (!ctx || modbus_connect(ctx) != 0) throw std::runtime_error("modbus connect failed");
  }
  ~PlcClient() {
    modbus_close(ctx);
    modbus_free(ctx);
  }
  int input_bit(int address) {
    uint8_t bit = 0xFF;
    return modbus_read_input_bits(ctx, address, 1, &bit) == 1 ? bit : -1;
  }
  int input_register(int address) {
    uint16_t value = 0;
    return modbus_read_input_registers(ctx, address, 1, &value) == 1 ? value : -1;
  }
};

TEST(SimFaults, DropOkLosesExactlyTheKthOk) {
  FaultSim s({"--drop-ok", "3"});
  StreamClient c = s.connect();
  c.send("G0X1\nG0X2\nG0X3\nG0X4\nG0X5\n");
  c.read_until([](const std::string&) { return false; }, 1.0);
  EXPECT_EQ(c.count("ok"), 4u) << c.buffer();
  const auto st = control_status(s.sim.control_port());
  EXPECT_EQ(st["oks_dropped"], 1);
  EXPECT_EQ(st["lines_received"], 5) << "the line itself was received and executed";
}

TEST(SimFaults, GarbledBytesReachTheControllerChanged) {
  FaultSim s({"--garble", "0.01", "--seed", "7", "--time-scale", "50"});
  StreamClient c = s.connect();
  const auto program = five_axis_program(300);
  // A garbled end of line merges two lines: one answer never comes, so the sender stalls (5 s).
  const StreamResult r = stream_counting(c, program, kGrblHalRxBytes, 5);
  const auto st = control_status(s.sim.control_port());
  ASSERT_GT(st["bytes_garbled"].get<int>(), 0);
  EXPECT_EQ(s.events("garble").size(), st["bytes_garbled"].get<std::size_t>());
  // Either the controller noticed (error:N) or what it executed differs from the program.
  bool changed = !r.errors.empty() || !r.finished;
  const auto blocks = executed_blocks(read_log(s.log));
  for (const auto& b : blocks)
    if (b["seq"].get<std::size_t>() <= program.size() && b["line"] != program[b["seq"].get<std::size_t>() - 1]) changed = true;
  EXPECT_TRUE(changed);
}

TEST(SimFaults, UnplugAtLineClosesTheLinkAndReplugBringsANewOne) {
  FaultSim s({"--unplug-at-line", "40", "--replug-after", "300", "--time-scale", "20"});
  StreamClient c = s.connect();
  const auto program = five_axis_program(200);
  const StreamResult r = stream_counting(c, program, kGrblHalRxBytes, 10);
  EXPECT_TRUE(c.closed()) << "the client sees the line drop";
  EXPECT_LE(r.oks, 40u);
  const auto st = control_status(s.sim.control_port());
  EXPECT_EQ(st["lines_received"], 40) << "bytes after line 40 never reached the controller";
  ASSERT_EQ(s.events("unplug").size(), 1u);
  ASSERT_TRUE(wait_status(s.sim.control_port(), [](const nlohmann::json& x) { return x["plugged"] == true; }, 3));
  StreamClient again = StreamClient::open_pty(s.link);
  EXPECT_TRUE(wait_controller(again)) << "a new port at the same path, and the controller on it";
}

TEST(SimFaults, AlarmAtLineStopsThereAndLocks) {
  FaultSim s({"--alarm-at-line", "20", "--time-scale", "20"});
  StreamClient c = s.connect();
  const auto program = five_axis_program(100);
  const StreamResult r = stream_counting(c, program, kGrblHalRxBytes, 20);
  ASSERT_EQ(r.alarms.size(), 1u) << c.buffer();
  EXPECT_EQ(r.alarms[0], "ALARM:1");
  const auto alarms = s.events("alarm");
  ASSERT_EQ(alarms.size(), 1u);
  EXPECT_EQ(alarms[0]["seq"], 20);
  for (const auto& b : executed_blocks(read_log(s.log))) {
    EXPECT_LE(b["seq"].get<int>(), 20);
    if (b["seq"] == 20) { EXPECT_EQ(b.value("completed", true), false); }
  }
  c.buffer().clear();
  c.send("G0X1\n");
  EXPECT_TRUE(c.wait_for("error:9", 2.0)) << c.buffer();
}

TEST(SimFaults, EstopAtTimeAlarmsTheCncAndOpensThePlcChain) {
  FaultSim s({"--estop-at", "0.5", "--modbus", "127.0.0.1:0"});
  StreamClient c = s.connect();
  PlcClient plc(s.sim.modbus_port());
  EXPECT_EQ(plc.input_bit(0), 1) << "estop_ok before";
  c.send("G1X300F6000\n");
  ASSERT_TRUE(c.wait_for("ALARM:10", 3.0)) << c.buffer();
  EXPECT_EQ(plc.input_bit(0), 0) << "estop_ok after";
  const auto st = control_status(s.sim.control_port());
  EXPECT_EQ(st["state"], "alarm");
  EXPECT_LT(st["position"][0].get<double>(), 300) << "the move was cut short";
  c.buffer().clear();
  c.send("$X\n");
  EXPECT_TRUE(c.wait_for("error:", 2.0)) << "no unlock while the e-stop is pressed: " << c.buffer();
}

TEST(SimFaults, PressureDropAtTimeTakesThePumpOutOfReady) {
  FaultSim s({"--modbus", "127.0.0.1:0", "--pressure-ramp", "0.2", "--pressure-drop-at", "1.0"});
  PlcClient plc(s.sim.modbus_port());
  ASSERT_EQ(modbus_write_bit(plc.ctx, 0, 1), 1);  // pump_enable
  const auto t0 = std::chrono::steady_clock::now();
  while (plc.input_bit(2) != 1 && seconds_since(t0) < 0.9) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  ASSERT_EQ(plc.input_bit(2), 1) << "pump_ready within the ramp";
  const int setpoint = [&] {
    uint16_t v = 0;
    modbus_read_registers(plc.ctx, 0, 1, &v);
    return static_cast<int>(v);
  }();
  EXPECT_GE(plc.input_register(0), setpoint * 95 / 100);
  while (seconds_since(t0) < 1.6) std::this_thread::sleep_for(std::chrono::milliseconds(50));
  EXPECT_EQ(plc.input_bit(2), 0) << "pump_ready after the drop";
  EXPECT_LT(plc.input_register(0), setpoint / 2);
  EXPECT_EQ(s.events("pressure_drop").size(), 1u);
}

// Pump and jet consent on, a heartbeat every 50 ms for 0.5 s: the pump comes to pressure and the
// valve opens. The heartbeat then falls silent.
// The PLC's watchdog in these tests: long enough that a loaded machine's scheduling stalls
// (hundreds of ms seen beside a build) never starve a heartbeat sent every 50 ms, so the jet
// goes off only when the test falls silent on purpose. The exact timing of the watchdog is
// checked with time as an argument (Plc.HeartbeatTimeoutLatchesAndResetNeedsHeartbeatsBack).
constexpr int kWatchdogMs = 1000;

// Opens the jet with a live heartbeat; returns the time just before the last heartbeat was sent:
// the PLC cannot have seen it earlier, so its watchdog cannot trip before this + kWatchdogMs.
std::chrono::steady_clock::time_point open_the_jet(PlcClient& plc) {
  std::chrono::steady_clock::time_point last_beat{};
  EXPECT_EQ(modbus_write_bit(plc.ctx, 0, 1), 1);  // pump_enable
  EXPECT_EQ(modbus_write_bit(plc.ctx, 2, 1), 1);  // jet_on
  for (uint16_t beat = 1; beat <= 10; ++beat) {
    if (beat > 1) std::this_thread::sleep_for(std::chrono::milliseconds(50));
    last_beat = std::chrono::steady_clock::now();
    EXPECT_EQ(modbus_write_register(plc.ctx, 1, beat), 1);
  }
  EXPECT_EQ(plc.input_bit(3), 1) << "jet_is_on while the heartbeat is alive";
  return last_beat;
}

TEST(SimFaults, SilentHeartbeatTurnsTheJetOffAndLatchesAnAlarm) {
  FaultSim s({"--modbus", "127.0.0.1:0", "--pressure-ramp", "0.1", "--heartbeat-timeout", std::to_string(kWatchdogMs)});
  PlcClient plc(s.sim.modbus_port());
  const auto last_beat = open_the_jet(plc);
  ASSERT_FALSE(::testing::Test::HasFailure());
  EXPECT_GE(plc.input_register(3), 10) << "heartbeat_seen";
  // Bounded wait for the event; the jet goes off by itself, with nothing more sent.
  while (plc.input_bit(3) == 1 && seconds_since(last_beat) < 10) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  EXPECT_EQ(plc.input_bit(3), 0) << "the jet is still on " << seconds_since(last_beat) << " s after the last heartbeat";
  EXPECT_GE(seconds_since(last_beat), kWatchdogMs / 1000.0) << "not before the watchdog's timeout";
  EXPECT_EQ(plc.input_bit(4), 1) << "alarm_latched";
  EXPECT_EQ(plc.input_register(6), 2) << "alarm_code heartbeat";
}

// `plc down`: the PLC off the network. Its connections drop, a new one is never answered, and
// its watchdog runs on: the host's silence trips it. `plc up` serves again, the alarm latched.
TEST(SimFaults, PlcDownAnswersNothingAndItsWatchdogRunsOn) {
  FaultSim s({"--modbus", "127.0.0.1:0", "--pressure-ramp", "0.1", "--heartbeat-timeout", std::to_string(kWatchdogMs)});
  PlcClient plc(s.sim.modbus_port());
  const auto last_beat = open_the_jet(plc);
  ASSERT_FALSE(::testing::Test::HasFailure());
  EXPECT_EQ(control(s.sim.control_port(), "plc down"), "ok");
  EXPECT_EQ(plc.input_bit(3), -1) << "the old connection is gone";
  {
    // The kernel may take a new connection, but the PLC never answers, and closes it unread
    // when the network is back: no request is served late.
    modbus_t* late = modbus_new_tcp("127.0.0.1", s.sim.modbus_port());
    modbus_set_response_timeout(late, 0, 300'000);
    uint8_t bit = 0;
    EXPECT_TRUE(modbus_connect(late) != 0 || modbus_read_input_bits(late, 3, 1, &bit) != 1);
    modbus_close(late);
    modbus_free(late);
  }
  // Past the watchdog (nobody can reach the PLC, so nothing else can be waited for).
  while (seconds_since(last_beat) < kWatchdogMs / 1000.0 + 0.2) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  EXPECT_EQ(control(s.sim.control_port(), "plc up"), "ok");
  PlcClient back(s.sim.modbus_port());
  EXPECT_EQ(back.input_bit(3), 0) << "the watchdog closed the jet while nobody could reach the PLC";
  EXPECT_EQ(back.input_bit(4), 1) << "alarm_latched";
  EXPECT_EQ(back.input_register(6), 2) << "alarm_code heartbeat";
  EXPECT_EQ(s.events("plc_down").size(), 1u);
  EXPECT_EQ(s.events("plc_up").size(), 1u);
}

// `time-scale K` at run time: the simulated clock goes on from where it was, at the new rate,
// and the PLC's watchdog keeps its wall-clock timeout and the heartbeat its wall-clock age. It
// used to keep the age in simulated seconds: slowing from 20× to 1× made a heartbeat 200 ms
// old look 4 s old, and the watchdog tripped at once.
TEST(SimFaults, ATimeScaleChangeKeepsTheClockAndTheWatchdogInWallTime) {
  FaultSim s({"--modbus", "127.0.0.1:0", "--pressure-ramp", "0.1", "--heartbeat-timeout", "1000", "--time-scale", "20"});
  PlcClient plc(s.sim.modbus_port());
  ASSERT_EQ(modbus_write_bit(plc.ctx, 0, 1), 1);
  ASSERT_EQ(modbus_write_bit(plc.ctx, 2, 1), 1);
  ASSERT_EQ(modbus_write_register(plc.ctx, 1, 1), 1);
  ASSERT_TRUE(wait_status(s.sim.control_port(), [&](const nlohmann::json&) { return plc.input_bit(3) == 1; }, 5));
  std::this_thread::sleep_for(std::chrono::milliseconds(200));  // the heartbeat is 200 ms (wall) old
  const double before = control_status(s.sim.control_port())["t"];
  EXPECT_EQ(control(s.sim.control_port(), "time-scale 1"), "ok");
  EXPECT_EQ(plc.input_bit(4), 0) << "a 200 ms old heartbeat is within a 1000 ms watchdog at any scale";
  EXPECT_EQ(plc.input_bit(3), 1);
  ASSERT_EQ(modbus_write_register(plc.ctx, 1, 2), 1);
  const nlohmann::json after = control_status(s.sim.control_port());
  EXPECT_EQ(after["time_scale"], 1.0);
  EXPECT_GE(after["t"].get<double>(), before) << "the clock does not go back";
  EXPECT_LT(after["t"].get<double>(), before + 5) << "nor jump ahead";
  const auto changes = s.events("time_scale");
  ASSERT_EQ(changes.size(), 1u);
  EXPECT_EQ(changes[0]["from"], 20.0);
  EXPECT_EQ(changes[0]["to"], 1.0);
  EXPECT_NE(control(s.sim.control_port(), "time-scale 0").find("error"), std::string::npos);
}

TEST(SimFaults, StallStopsTakingLinesForItsDuration) {
  FaultSim s({"--stall-at", "0.3", "--stall-for", "600"});
  StreamClient c = s.connect();
  // One short line at a time for 1.5 s: the gap between two oks shows the stall. (An ok comes
  // when the line is queued, so a dwell per line keeps the queue from racing ahead.)
  double longest_gap = 0;
  const auto t0 = std::chrono::steady_clock::now();
  auto last = t0;
  for (int i = 0; seconds_since(t0) < 1.5; ++i) {
    c.buffer().clear();
    c.send("G4P0.01\n");
    ASSERT_TRUE(c.wait_for("ok", 3.0)) << "line " << i;
    longest_gap = std::max(longest_gap, seconds_since(last));
    last = std::chrono::steady_clock::now();
  }
  EXPECT_GT(longest_gap, 0.5);
  EXPECT_LT(longest_gap, 1.5);
  EXPECT_EQ(s.events("stall").size(), 1u);
  EXPECT_EQ(s.events("stall_end").size(), 1u);
}

TEST(SimFaults, ControlSocketInjectsAtRunTime) {
  FaultSim s({"--modbus", "127.0.0.1:0"});
  StreamClient c = s.connect();
  const int port = s.sim.control_port();
  EXPECT_EQ(control(port, "door open"), "ok");
  PlcClient plc(s.sim.modbus_port());
  EXPECT_EQ(plc.input_bit(1), 0) << "door_closed";
  EXPECT_EQ(control(port, "estop on"), "ok");
  EXPECT_TRUE(c.wait_for("ALARM:10", 2.0)) << c.buffer();
  EXPECT_EQ(control(port, "estop off"), "ok");
  EXPECT_EQ(control(port, "unplug"), "ok");
  c.read_until([](const std::string&) { return false; }, 0.3);
  EXPECT_TRUE(c.closed());
  EXPECT_NE(control(port, "warp 9").find("error: unknown command"), std::string::npos);
  EXPECT_NE(control(port, "stall soon").find("error"), std::string::npos);
}

TEST(SimFaults, SimCoilsInjectThroughModbus) {
  FaultSim s({"--modbus", "127.0.0.1:0"});
  StreamClient c = s.connect();
  PlcClient plc(s.sim.modbus_port());
  ASSERT_EQ(modbus_write_bit(plc.ctx, 100, 1), 1);  // sim-only coil: e-stop
  EXPECT_TRUE(c.wait_for("ALARM:10", 2.0)) << c.buffer();
  EXPECT_EQ(plc.input_bit(0), 0);
}

}  // namespace
}  // namespace lamina::sim::testing
