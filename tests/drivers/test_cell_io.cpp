// CellIo against the lamina-sim PLC (a separate process): bringing the cell up, the heartbeat,
// interlock faults while cutting, refusals before cutting, an unreachable PLC, and shutting down.
#include <gtest/gtest.h>

#include <atomic>
#include <mutex>

#include <fmt/format.h>

#include "lamina/drivers/cell_io.hpp"
#include "modbus_test_client.hpp"

namespace lamina::drivers {
namespace {
using namespace testing;

CellIoSettings settings_for(int port) {
  CellIoSettings s;
  s.plc.port = port;
  s.poll_period_s = 0.05;
  s.heartbeat_period_s = 0.1;  // the sim's watchdog is 500 ms
  s.pump_ready_timeout_s = 3;
  return s;
}

// Records faults as the callback sees them (on the Modbus thread).
struct FaultLog {
  std::mutex mutex;
  std::vector<CellFaultReport> seen;
  std::chrono::steady_clock::time_point first_at;
  void attach(CellIo& cell) {
    cell.on_fault([this](const CellFaultReport& f) {
      std::lock_guard lock(mutex);
      if (seen.empty()) first_at = std::chrono::steady_clock::now();
      seen.push_back(f);
    });
  }
  std::size_t count() {
    std::lock_guard lock(mutex);
    return seen.size();
  }
};

TEST(CellIo, PrepareCutBringsTheCellUp) {
  SimCell cell;
  CellIo io(settings_for(cell.sim.modbus_port()));
  auto r = io.prepare_cut();
  ASSERT_TRUE(r) << r.error().message;
  PlcProbe plc(cell.sim.modbus_port());
  EXPECT_EQ(plc.coil(map::kCoilPump), 1);
  EXPECT_EQ(plc.coil(map::kCoilAbrasive), 1);
  EXPECT_EQ(plc.coil(map::kCoilJet), 1);
  EXPECT_EQ(plc.input(map::kInputPumpReady), 1);
  EXPECT_EQ(plc.input(map::kInputJetIsOn), 1);
  const CellStatus st = io.status();
  EXPECT_TRUE(st.connected);
  EXPECT_NEAR(st.pressure_mpa, 380.0, 20.0);
  EXPECT_FALSE(io.fault());
}

TEST(CellIo, HeartbeatKeepsTheWatchdogQuietAndItsSilenceTripsIt) {
  SimCell cell;
  PlcProbe plc(cell.sim.modbus_port());
  auto io = std::make_unique<CellIo>(settings_for(cell.sim.modbus_port()));
  ASSERT_TRUE(io->prepare_cut());
  std::this_thread::sleep_for(std::chrono::seconds(2));  // four watchdog timeouts
  EXPECT_EQ(plc.input(map::kInputAlarmLatched), 0);
  EXPECT_EQ(plc.input(map::kInputJetIsOn), 1);
  EXPECT_FALSE(io->fault());
  io.reset();  // no finish_cut: the heartbeat just stops (the destructor closes the jet)
  EXPECT_EQ(plc.coil(map::kCoilJet), 0);
  EXPECT_TRUE(eventually([&] { return plc.in_reg(map::kInAlarmCode) == 2; }, 2.0)) << "heartbeat alarm latched";
}

// Issue 18: the heartbeat stopped with every finished cut, so the PLC's watchdog latched its
// alarm in each gap between sheets and the next prepare reset it without a word. It goes on
// between cuts now: the register keeps changing after finish_cut (waited for, not slept on).
TEST(CellIo, TheHeartbeatGoesOnBetweenCuts) {
  SimCell cell;
  PlcProbe plc(cell.sim.modbus_port());
  CellIo io(settings_for(cell.sim.modbus_port()));
  ASSERT_TRUE(io.prepare_cut());
  ASSERT_TRUE(io.finish_cut());
  for (int beat = 0; beat < 3; ++beat) {
    const int before = plc.hold(map::kHoldHeartbeat);
    EXPECT_TRUE(eventually([&] { return plc.hold(map::kHoldHeartbeat) != before; }, 5.0))
        << "beat " << beat << " after the cut finished";
  }
  EXPECT_EQ(plc.coil(map::kCoilJet), 0) << "the jet stays off between cuts";
  ASSERT_TRUE(io.prepare_cut()) << "the next sheet starts without an alarm to reset";
  EXPECT_EQ(plc.input(map::kInputAlarmLatched), 0);
}

// One interlock fault while cutting: reported once, within two poll periods, jet consent removed.
void expect_fault_while_cutting(const std::string& command, CellFault expected, const std::string& word) {
  SimCell cell;
  PlcProbe plc(cell.sim.modbus_port());
  const auto settings = settings_for(cell.sim.modbus_port());
  CellIo io(settings);
  FaultLog faults;
  faults.attach(io);
  ASSERT_TRUE(io.prepare_cut());
  const auto t0 = std::chrono::steady_clock::now();
  ASSERT_EQ(control(cell.sim.control_port(), command), "ok");
  ASSERT_TRUE(eventually([&] { return faults.count() > 0; }, 2.0)) << "no fault after " << command;
  const double latency_s = std::chrono::duration<double>(faults.first_at - t0).count();
  // Two poll periods, plus the control socket's own round trip and scheduling slack on a busy box.
  EXPECT_LT(latency_s, 2 * settings.poll_period_s + 0.05) << command;
  ::testing::Test::RecordProperty("fault_latency_ms", static_cast<int>(latency_s * 1000));
  EXPECT_EQ(plc.coil(map::kCoilJet), 0) << "jet consent must be withdrawn";
  EXPECT_EQ(plc.input(map::kInputJetIsOn), 0);
  ASSERT_TRUE(io.fault());
  EXPECT_EQ(io.fault()->fault, expected);
  EXPECT_NE(io.fault()->message.find(word), std::string::npos) << io.fault()->message;
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  EXPECT_EQ(faults.count(), 1u) << "the callback runs once";
}

TEST(CellIo, EstopWhileCuttingIsAFaultAndTheJetGoesOff) {
  expect_fault_while_cutting("estop on", CellFault::estop, "e-stop");
}

TEST(CellIo, DoorOpenedWhileCuttingIsAFault) { expect_fault_while_cutting("door open", CellFault::door_open, "door"); }

// A fault the simulator schedules from its own start (--estop-at, --pressure-drop-at) lands
// during the cut or, on a loaded machine, before the prepare is through: either way it is seen,
// named, and the jet stays off.
template <class Check>
void expect_scheduled_fault(const std::vector<std::string>& sim_flags, LinkErrorCode refused_as, const std::string& word,
                            Check check_fault) {
  SimCell cell(sim_flags);
  PlcProbe plc(cell.sim.modbus_port());
  CellIo io(settings_for(cell.sim.modbus_port()));
  if (auto prepared = io.prepare_cut(); !prepared) {
    EXPECT_EQ(prepared.error().code, refused_as) << prepared.error().message;
    EXPECT_NE(prepared.error().message.find(word), std::string::npos) << prepared.error().message;
  } else {
    ASSERT_TRUE(eventually([&] { return io.fault().has_value(); }, 30.0));
    check_fault(*io.fault());
  }
  EXPECT_EQ(plc.coil(map::kCoilJet), 0);
}

TEST(CellIo, ScheduledEstopIsSeenToo) {
  expect_scheduled_fault({"--estop-at", "1.5"}, LinkErrorCode::interlock, "e-stop",
                         [](const auto& f) { EXPECT_EQ(f.fault, CellFault::estop) << f.message; });
}

TEST(CellIo, PressureDropIsAFault) {
  expect_scheduled_fault({"--pressure-drop-at", "1.5"}, LinkErrorCode::interlock, "pressure", [](const auto& f) {
    EXPECT_EQ(f.fault, CellFault::pressure_low) << f.message;
    EXPECT_NE(f.message.find("MPa"), std::string::npos) << f.message;
  });
}

TEST(CellIo, PrepareWithTheDoorOpenIsRefusedNamingTheDoor) {
  SimCell cell;
  ASSERT_EQ(control(cell.sim.control_port(), "door open"), "ok");
  CellIo io(settings_for(cell.sim.modbus_port()));
  auto r = io.prepare_cut();
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, LinkErrorCode::interlock);
  EXPECT_NE(r.error().message.find("door"), std::string::npos) << r.error().message;
  PlcProbe plc(cell.sim.modbus_port());
  EXPECT_EQ(plc.coil(map::kCoilPump), 0);
  EXPECT_EQ(plc.coil(map::kCoilJet), 0);
}

// A shop names its PLC ("plc-cell1"), or gives an IPv6 address: both must reach it.
TEST(CellIo, APlcNamedByItsHostNameIsReached) {
  SimCell cell;
  auto settings = settings_for(cell.sim.modbus_port());
  settings.plc.host = "localhost";  // may resolve to ::1 first: the sim listens on 127.0.0.1 only
  CellIo io(settings);
  auto r = io.prepare_cut();
  ASSERT_TRUE(r) << r.error().message;
  EXPECT_TRUE(io.status().connected);
  io.jet_off();
}

TEST(CellIo, AHostNameThatDoesNotResolveIsNamedInTheError) {
  auto settings = settings_for(502);
  settings.plc.host = "no-such-plc.invalid";  // RFC 2606: never resolves
  settings.plc.max_reconnects = 1;
  CellIo io(settings);
  auto r = io.prepare_cut();
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("cannot resolve 'no-such-plc.invalid'"), std::string::npos) << r.error().message;
}

TEST(CellIo, UnreachablePlcGivesUpAfterBoundedReconnects) {
  auto settings = settings_for(unused_port());
  settings.plc.max_reconnects = 3;
  CellIo io(settings);
  const auto t0 = std::chrono::steady_clock::now();
  auto r = io.prepare_cut();
  const double took_s = seconds_since(t0);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, LinkErrorCode::modbus_error);
  EXPECT_NE(r.error().message.find("after 3 reconnects"), std::string::npos) << r.error().message;
  EXPECT_LT(took_s, 3.0);
}

TEST(CellIo, SilentPlcTimesOutAndGivesUpAfterBoundedReconnects) {
  // A listener that never answers: connects succeed (the kernel's backlog), every request times out.
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  ::inet_pton(AF_INET, "127.0.0.1", &addr.sin_addr);
  ASSERT_EQ(::bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr), 0);
  ASSERT_EQ(::listen(fd, 16), 0);
  socklen_t len = sizeof addr;
  ::getsockname(fd, reinterpret_cast<sockaddr*>(&addr), &len);
  auto settings = settings_for(ntohs(addr.sin_port));
  settings.plc.response_timeout_s = 0.2;
  settings.plc.max_reconnects = 2;
  {
    CellIo io(settings);
    const auto t0 = std::chrono::steady_clock::now();
    auto r = io.prepare_cut();
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().code, LinkErrorCode::modbus_error);
    EXPECT_NE(r.error().message.find("timed out"), std::string::npos) << r.error().message;
    EXPECT_LT(seconds_since(t0), 3.0);
  }
  ::close(fd);
}

TEST(CellIo, PlcLostWhileCuttingIsLinkLostWithoutHanging) {
  auto cell = std::make_unique<SimCell>();
  CellIo io(settings_for(cell->sim.modbus_port()));
  FaultLog faults;
  faults.attach(io);
  ASSERT_TRUE(io.prepare_cut());
  cell->sim.stop();
  ASSERT_TRUE(eventually([&] { return faults.count() > 0; }, 5.0));
  EXPECT_EQ(io.fault()->fault, CellFault::link_lost) << io.fault()->message;
  EXPECT_GE(io.status().reconnects, 3);
  const auto t0 = std::chrono::steady_clock::now();
  EXPECT_FALSE(io.finish_cut());  // still unreachable: an error, not a hang
  EXPECT_LT(seconds_since(t0), 3.0);
}

// Found by the fault campaign: with the PLC off the network, the cut's feed hold waited in
// CellIo behind the reconnects, and reached the CNC when the PLC came back — after the resume
// had reset the CNC, so the new program started held. A late cycle start would start a
// machine by itself. Presses that cannot be made within 0.5 s are dropped now.
TEST(CellIo, AButtonPressTheUnreachablePlcCouldNotTakeIsNotMadeLate) {
  SimCell cell;
  CellIo io(settings_for(cell.sim.modbus_port()));
  ASSERT_TRUE(io.prepare_cut());
  ASSERT_EQ(sim::testing::control(cell.sim.control_port(), "plc down"), "ok");
  io.feed_hold();  // the Modbus thread is in its reconnects now
  io.cycle_start();
  std::this_thread::sleep_for(std::chrono::milliseconds(900));
  ASSERT_EQ(sim::testing::control(cell.sim.control_port(), "plc up"), "ok");
  ASSERT_TRUE(eventually([&] { return io.refresh().has_value(); }, 10.0)) << "the PLC answers again";
  bool up = false;
  for (const auto& r : sim::testing::read_log(cell.log())) {
    if (r.value("event", "") == "plc_up") up = true;
    EXPECT_FALSE(up && r.value("event", "") == "plc_button") << "a press made late: " << r.dump();
  }
  EXPECT_TRUE(up);
}

TEST(CellIo, FinishCutLeavesPumpAbrasiveAndJetOff) {
  SimCell cell;
  PlcProbe plc(cell.sim.modbus_port());
  CellIo io(settings_for(cell.sim.modbus_port()));
  ASSERT_TRUE(io.prepare_cut());
  auto r = io.finish_cut();
  ASSERT_TRUE(r) << r.error().message;
  EXPECT_EQ(plc.coil(map::kCoilJet), 0);
  EXPECT_EQ(plc.coil(map::kCoilAbrasive), 0);
  EXPECT_EQ(plc.coil(map::kCoilPump), 0);
  EXPECT_EQ(plc.input(map::kInputJetIsOn), 0);
}

TEST(CellIo, JetOffFromAnotherThreadClosesTheJet) {
  SimCell cell;
  PlcProbe plc(cell.sim.modbus_port());
  CellIo io(settings_for(cell.sim.modbus_port()));
  ASSERT_TRUE(io.prepare_cut());
  const auto t0 = std::chrono::steady_clock::now();
  std::thread([&] { io.jet_off(); }).join();
  ASSERT_TRUE(eventually([&] { return plc.coil(map::kCoilJet) == 0; }, 1.0));
  EXPECT_LT(seconds_since(t0), 0.5 + 0.1) << "at most one response timeout";
  EXPECT_EQ(plc.coil(map::kCoilPump), 1) << "jet_off touches the jet only";
}

// A drip-fed program running on the simulated CNC (20 moves of 1 s), the PLC watching it.
struct RunningDripFeed {
  SimCell cell{{"--personality", "xonxoff", "--time-scale", "1"}};
  PlcProbe plc{cell.sim.modbus_port()};
  sim::testing::StreamClient client = sim::testing::StreamClient::open_pty(cell.dir.file("cnc"));
  // False unless the program went out and the PLC reads the CNC running.
  bool start() {
    std::string program = "%\n";
    for (int i = 0; i < 20; ++i) program += fmt::format("G1X{}F600\n", 10 * (i % 2));
    return client.send(program) && eventually([&] { return plc.in_reg(map::kInCncState) == 1; }, 3.0);
  }
};

// A drip-fed program is running, held by the PLC's button, then reset by its other button: the
// CNC's queue is gone and it reads idle when reset_cnc() returns.
TEST(CellIo, ResetCncFlushesAHeldProgramAndReturnsWhenTheCncIsIdle) {
  RunningDripFeed feed;
  ASSERT_TRUE(feed.start()) << "running";
  SimCell& cell = feed.cell;
  PlcProbe& plc = feed.plc;
  CellIo io(settings_for(cell.sim.modbus_port()));
  io.feed_hold();
  ASSERT_TRUE(eventually([&] { return plc.in_reg(map::kInCncState) == 3; }, 3.0)) << "held";
  EXPECT_GT(sim::testing::control_status(cell.sim.control_port())["queued_blocks"].get<int>(), 0);
  const auto r = io.reset_cnc();
  ASSERT_TRUE(r) << r.error().message;
  EXPECT_EQ(plc.in_reg(map::kInCncState), 0);
  EXPECT_EQ(io.status().cnc_state, ControllerState::idle);
  EXPECT_EQ(sim::testing::control_status(cell.sim.control_port())["queued_blocks"], 0) << "the queue was flushed";
}

// hold_cnc() returns only once the PLC has handed the press on: the CNC reads held at once,
// so a reset over the line that follows cannot be overtaken by a late hold.
TEST(CellIo, HoldCncReturnsOnceTheCncIsHeld) {
  RunningDripFeed feed;
  ASSERT_TRUE(feed.start()) << "running";
  SimCell& cell = feed.cell;
  PlcProbe& plc = feed.plc;
  CellIo io(settings_for(cell.sim.modbus_port()));
  const auto r = io.hold_cnc();
  ASSERT_TRUE(r) << r.error().message;
  EXPECT_EQ(plc.in_reg(map::kInCncState), 3) << "held when hold_cnc() returned";
  EXPECT_EQ(io.status().cnc_state, ControllerState::hold);
  // An idle CNC stands still already: no wait beyond the PLC's scan.
  ASSERT_TRUE(io.reset_cnc());
  const auto t0 = std::chrono::steady_clock::now();
  ASSERT_TRUE(io.hold_cnc());
  EXPECT_LT(seconds_since(t0), 1.0);
}

// The e-stop outlives any reset: reset_cnc() says the CNC stayed in alarm, within its timeout.
TEST(CellIo, ResetCncWithTheEstopPressedNamesTheAlarm) {
  SimCell cell;
  ASSERT_EQ(sim::testing::control(cell.sim.control_port(), "estop on"), "ok");
  PlcProbe plc(cell.sim.modbus_port());
  ASSERT_TRUE(eventually([&] { return plc.in_reg(map::kInCncState) == 4; }, 3.0)) << "the e-stop reached the CNC";
  auto settings = settings_for(cell.sim.modbus_port());
  settings.cnc_reset_timeout_s = 0.5;
  CellIo io(settings);
  const auto t0 = std::chrono::steady_clock::now();
  const auto r = io.reset_cnc();
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("alarm"), std::string::npos) << r.error().message;
  EXPECT_LT(seconds_since(t0), 2.0);
}

}  // namespace
}  // namespace lamina::drivers
