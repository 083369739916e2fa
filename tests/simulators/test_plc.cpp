// The PLC model alone, on a simulated clock: pump ramp, interlocks, watchdog, alarms, mailbox,
// and the encoding of the CNC snapshot into input registers.
#include <gtest/gtest.h>

#include <string>

#include "plc.hpp"

namespace lamina::sim {
namespace {
namespace mm = modbus_map;

PlcConfig test_config() {
  PlcConfig c;
  c.pressure_ramp_s = 2.0;
  c.pressure_ready_fraction = 0.95;
  c.default_setpoint_01mpa = 3800;
  c.heartbeat_timeout_s = 1.0;
  return c;
}

// A client write: set coils/holding as a Modbus write would, then tell the PLC.
struct PlcCell {
  Plc plc{test_config()};
  double now = 0;
  CncSnapshot cnc;

  PlcRegisters& r() { return plc.registers(); }
  void coil(int address, bool on) {
    r().coils[address] = on;
    plc.after_client_write(now);
  }
  void hold(int address, std::uint16_t value) {
    r().holding[address] = value;
    plc.after_client_write(now);
  }
  void run_to(double t_s, double step_s = 0.01) {
    while (now + 1e-12 < t_s) {
      now = std::min(t_s, now + step_s);
      plc.tick(now, cnc);
    }
  }
  bool input(int address) { return r().inputs[address] != 0; }
  std::uint16_t in_reg(int address) { return r().input_registers[address]; }
  // Pump at pressure, abrasive on, jet consent given: everything the jet needs.
  void ready_to_cut() {
    plc.tick(now, cnc);
    coil(mm::kCoilPumpEnable, true);
    run_to(now + 2.5);
    coil(mm::kCoilJetOn, true);
  }
  void submit(std::uint16_t seq, const std::string& text) {
    auto& h = r().holding;
    h[mm::kHoldMailboxLength] = static_cast<std::uint16_t>(text.size());
    for (std::size_t i = 0; i < text.size(); ++i) {
      auto& word = h[mm::kHoldMailboxText + i / 2];
      const auto c = static_cast<unsigned char>(text[i]);
      word = i % 2 == 0 ? static_cast<std::uint16_t>(c << 8) : static_cast<std::uint16_t>(word | c);
    }
    hold(mm::kHoldMailboxSeq, seq);
  }
};

TEST(Plc, PowerOnState) {
  PlcCell cell;
  EXPECT_EQ(cell.r().holding[mm::kHoldPressureSetpoint], 3800);
  EXPECT_EQ(cell.r().holding[mm::kHoldAbrasiveSetpoint], 350);
  EXPECT_TRUE(cell.input(mm::kInputEstopOk));
  EXPECT_TRUE(cell.input(mm::kInputDoorClosed));
  EXPECT_FALSE(cell.input(mm::kInputPumpReady));
  EXPECT_FALSE(cell.input(mm::kInputJetIsOn));
  EXPECT_EQ(cell.in_reg(mm::kInHopperLevel), 500);  // 50 kg in 0.1 kg
  EXPECT_EQ(cell.plc.alarm_code(), mm::kAlarmNone);
}

TEST(Plc, PressureRampsLinearlyAndPumpReadyAtTheFraction) {
  PlcCell cell;
  cell.plc.tick(0, cell.cnc);
  cell.coil(mm::kCoilPumpEnable, true);
  cell.run_to(1.0);
  EXPECT_NEAR(cell.in_reg(mm::kInPressure), 1900, 1);  // half the set point at half the ramp
  EXPECT_FALSE(cell.input(mm::kInputPumpReady));
  cell.run_to(1.89);  // 0.945 × set point
  EXPECT_FALSE(cell.input(mm::kInputPumpReady));
  cell.run_to(1.91);  // 0.955 × set point
  EXPECT_TRUE(cell.input(mm::kInputPumpReady));
  cell.run_to(3.0);
  EXPECT_EQ(cell.in_reg(mm::kInPressure), 3800);  // holds at the set point

  cell.coil(mm::kCoilPumpEnable, false);
  EXPECT_FALSE(cell.input(mm::kInputPumpReady));  // stopped pump is never ready
  cell.run_to(4.0);
  EXPECT_NEAR(cell.in_reg(mm::kInPressure), 1900, 1);  // falls at the same rate
  cell.run_to(6.0);
  EXPECT_EQ(cell.in_reg(mm::kInPressure), 0);
}

TEST(Plc, SetpointChangeRetargetsThePressure) {
  PlcCell cell;
  cell.ready_to_cut();
  cell.hold(mm::kHoldPressureSetpoint, 2000);
  cell.run_to(cell.now + 2.0);
  EXPECT_EQ(cell.in_reg(mm::kInPressure), 2000);
  EXPECT_TRUE(cell.input(mm::kInputPumpReady));
  cell.hold(mm::kHoldPressureSetpoint, 0);  // no set point: never ready
  EXPECT_FALSE(cell.input(mm::kInputPumpReady));
}

TEST(Plc, AbrasiveFollowsItsCoilAndEmptiesTheHopper) {
  PlcCell cell;
  cell.plc.tick(0, cell.cnc);
  cell.hold(mm::kHoldAbrasiveSetpoint, 1000);  // 1 kg/min
  EXPECT_EQ(cell.in_reg(mm::kInAbrasiveFlow), 0);
  cell.coil(mm::kCoilAbrasiveEnable, true);
  EXPECT_EQ(cell.in_reg(mm::kInAbrasiveFlow), 1000);
  cell.run_to(60.0, 0.5);
  EXPECT_EQ(cell.in_reg(mm::kInHopperLevel), 490);  // 49.0 kg
  cell.coil(mm::kCoilAbrasiveEnable, false);
  EXPECT_EQ(cell.in_reg(mm::kInAbrasiveFlow), 0);
  cell.run_to(120.0, 0.5);
  EXPECT_EQ(cell.in_reg(mm::kInHopperLevel), 490);
  cell.coil(mm::kCoilAbrasiveEnable, true);
  cell.run_to(120.0 + 60.0 * 50, 5.0);  // far past empty
  EXPECT_EQ(cell.in_reg(mm::kInHopperLevel), 0);
  EXPECT_EQ(cell.in_reg(mm::kInAbrasiveFlow), 0);  // nothing left to feed
}

TEST(Plc, JetNeedsEveryCondition) {
  PlcCell cell;
  cell.ready_to_cut();
  ASSERT_TRUE(cell.input(mm::kInputJetIsOn));
  ASSERT_TRUE(cell.plc.jet_is_on());

  cell.coil(mm::kCoilJetOn, false);  // the supervisor's independent off path
  EXPECT_FALSE(cell.input(mm::kInputJetIsOn));
  cell.coil(mm::kCoilJetOn, true);
  EXPECT_TRUE(cell.input(mm::kInputJetIsOn));

  cell.coil(mm::kCoilSimDoorOpen, true);
  EXPECT_FALSE(cell.input(mm::kInputDoorClosed));
  EXPECT_FALSE(cell.input(mm::kInputJetIsOn));
  EXPECT_FALSE(cell.input(mm::kInputAlarmLatched));  // a door is no alarm
  cell.coil(mm::kCoilSimDoorOpen, false);
  EXPECT_TRUE(cell.input(mm::kInputJetIsOn));

  cell.plc.set_door_open(true);  // the flag / control-socket path
  EXPECT_FALSE(cell.plc.jet_is_on());
  EXPECT_EQ(cell.r().coils[mm::kCoilSimDoorOpen], 1);  // reads back through the coil
  cell.plc.set_door_open(false);
  EXPECT_TRUE(cell.plc.jet_is_on());

  cell.coil(mm::kCoilPumpEnable, false);
  EXPECT_FALSE(cell.input(mm::kInputJetIsOn));
}

TEST(Plc, CncJetRequestIsReportedNotObeyed) {
  PlcCell cell;
  cell.cnc.jet_request = true;
  cell.plc.tick(0, cell.cnc);
  EXPECT_TRUE(cell.input(mm::kInputCncJetRequest));
  EXPECT_FALSE(cell.input(mm::kInputJetIsOn));  // no pump, no consent
}

TEST(Plc, EstopLatchesAndStopsThePump) {
  PlcCell cell;
  cell.ready_to_cut();
  cell.coil(mm::kCoilSimEstop, true);
  EXPECT_TRUE(cell.plc.estop_pressed());
  EXPECT_FALSE(cell.input(mm::kInputEstopOk));
  EXPECT_FALSE(cell.input(mm::kInputJetIsOn));
  EXPECT_FALSE(cell.input(mm::kInputPumpReady));
  EXPECT_EQ(cell.in_reg(mm::kInAlarmCode), mm::kAlarmEstop);
  cell.run_to(cell.now + 3.0);
  EXPECT_EQ(cell.in_reg(mm::kInPressure), 0);

  cell.coil(mm::kCoilAlarmReset, true);  // refused: still pressed
  EXPECT_EQ(cell.r().coils[mm::kCoilAlarmReset], 0);
  EXPECT_TRUE(cell.input(mm::kInputAlarmLatched));

  cell.coil(mm::kCoilSimEstop, false);  // released, but still latched: the pump stays off
  cell.run_to(cell.now + 1.0);
  EXPECT_TRUE(cell.input(mm::kInputAlarmLatched));
  EXPECT_EQ(cell.in_reg(mm::kInPressure), 0);

  cell.coil(mm::kCoilAlarmReset, true);
  EXPECT_FALSE(cell.input(mm::kInputAlarmLatched));
  EXPECT_EQ(cell.in_reg(mm::kInAlarmCode), mm::kAlarmNone);
  cell.run_to(cell.now + 2.5);
  EXPECT_TRUE(cell.input(mm::kInputJetIsOn));  // coils kept their values: the cell comes back
}

TEST(Plc, EstopThroughTheSetterLatchesAtOnce) {
  PlcCell cell;
  cell.plc.set_estop(true);
  EXPECT_EQ(cell.plc.alarm_code(), mm::kAlarmEstop);
  EXPECT_EQ(cell.r().coils[mm::kCoilSimEstop], 1);
  cell.plc.set_estop(false);
  EXPECT_FALSE(cell.plc.estop_pressed());
  EXPECT_EQ(cell.plc.alarm_code(), mm::kAlarmEstop);  // until reset
}

TEST(Plc, PressureDropTakesPumpReadyAway) {
  PlcCell cell;
  cell.ready_to_cut();
  cell.coil(mm::kCoilSimPressureDrop, true);
  cell.run_to(cell.now + 0.2);
  EXPECT_FALSE(cell.input(mm::kInputPumpReady));
  EXPECT_FALSE(cell.input(mm::kInputJetIsOn));
  cell.run_to(cell.now + 3.0);
  EXPECT_EQ(cell.in_reg(mm::kInPressure), 1140);  // 0.3 × 3800
  EXPECT_FALSE(cell.input(mm::kInputAlarmLatched));
  cell.plc.set_pressure_drop(false);
  cell.run_to(cell.now + 2.0);
  EXPECT_TRUE(cell.input(mm::kInputJetIsOn));
}

TEST(Plc, StallIsACoilTheCncReads) {
  PlcCell cell;
  EXPECT_FALSE(cell.plc.stall());
  cell.coil(mm::kCoilSimStall, true);
  EXPECT_TRUE(cell.plc.stall());
  cell.plc.set_stall(false);
  EXPECT_EQ(cell.r().coils[mm::kCoilSimStall], 0);
}

TEST(Plc, HeartbeatWatchdogIsArmedByTheFirstChange) {
  PlcCell cell;
  cell.ready_to_cut();
  cell.run_to(cell.now + 5.0);  // never written: not supervised
  EXPECT_TRUE(cell.input(mm::kInputJetIsOn));
  cell.hold(mm::kHoldHeartbeat, 1);
  EXPECT_EQ(cell.in_reg(mm::kInHeartbeatSeen), 1);
  for (std::uint16_t beat = 2; beat < 10; ++beat) {  // every 0.5 s: alive
    cell.run_to(cell.now + 0.5);
    cell.hold(mm::kHoldHeartbeat, beat);
  }
  EXPECT_EQ(cell.in_reg(mm::kInHeartbeatSeen), 9);
  EXPECT_TRUE(cell.input(mm::kInputJetIsOn));
  cell.hold(mm::kHoldHeartbeat, 9);  // the same value is no heartbeat
  EXPECT_EQ(cell.in_reg(mm::kInHeartbeatSeen), 9);
}

// A supervisor that died mid-cut: the watchdog holds the CNC (it would run its queue on dry);
// one that stopped beating between sheets leaves an idle CNC alone (held, it would refuse the
// next sheet).
TEST(Plc, HeartbeatTimeoutHoldsACncInItsCycleOnly) {
  for (const bool cutting : {true, false}) {
    PlcCell cell;
    cell.ready_to_cut();
    cell.cnc.state = cutting ? 1 : 0;
    cell.cnc.jet_request = cutting;
    cell.hold(mm::kHoldHeartbeat, 1);
    cell.run_to(cell.now + 1.1);
    ASSERT_TRUE(cell.input(mm::kInputAlarmLatched));
    EXPECT_EQ(cell.plc.take_cnc_buttons().feed_hold, cutting) << (cutting ? "cutting" : "idle");
  }
}

TEST(Plc, HeartbeatTimeoutLatchesAndResetNeedsHeartbeatsBack) {
  PlcCell cell;
  cell.ready_to_cut();
  cell.hold(mm::kHoldHeartbeat, 1);
  const double beat_s = cell.now;
  cell.run_to(beat_s + 0.99);
  EXPECT_TRUE(cell.input(mm::kInputJetIsOn));
  cell.run_to(beat_s + 1.02);
  EXPECT_FALSE(cell.input(mm::kInputJetIsOn));
  EXPECT_TRUE(cell.input(mm::kInputAlarmLatched));
  EXPECT_EQ(cell.in_reg(mm::kInAlarmCode), mm::kAlarmHeartbeat);

  cell.coil(mm::kCoilAlarmReset, true);  // heartbeat still silent: refused
  EXPECT_EQ(cell.in_reg(mm::kInAlarmCode), mm::kAlarmHeartbeat);

  cell.hold(mm::kHoldHeartbeat, 2);  // a late heartbeat alone does not clear the latch
  EXPECT_TRUE(cell.input(mm::kInputAlarmLatched));
  EXPECT_FALSE(cell.input(mm::kInputJetIsOn));
  cell.coil(mm::kCoilAlarmReset, true);
  EXPECT_FALSE(cell.input(mm::kInputAlarmLatched));
  EXPECT_TRUE(cell.input(mm::kInputJetIsOn));

  // A heartbeat and the reset in one write (the order inside the PLC makes it work).
  cell.run_to(cell.now + 1.5);
  ASSERT_EQ(cell.in_reg(mm::kInAlarmCode), mm::kAlarmHeartbeat);
  cell.r().holding[mm::kHoldHeartbeat] = 3;
  cell.r().coils[mm::kCoilAlarmReset] = 1;
  cell.plc.after_client_write(cell.now);
  EXPECT_EQ(cell.in_reg(mm::kInAlarmCode), mm::kAlarmNone);
}

TEST(Plc, ZeroTimeoutDisablesTheWatchdog) {
  PlcConfig config = test_config();
  config.heartbeat_timeout_s = 0;
  Plc plc(config);
  plc.registers().holding[mm::kHoldHeartbeat] = 7;
  plc.after_client_write(0);
  plc.tick(100, CncSnapshot{});
  EXPECT_EQ(plc.alarm_code(), mm::kAlarmNone);
  EXPECT_EQ(plc.registers().input_registers[mm::kInHeartbeatSeen], 1);
}

TEST(Plc, FirstAlarmIsShownUntilItsCauseIsCleared) {
  PlcCell cell;
  cell.ready_to_cut();
  cell.hold(mm::kHoldHeartbeat, 1);
  cell.coil(mm::kCoilSimEstop, true);
  cell.run_to(cell.now + 1.5);  // heartbeat lost too
  EXPECT_EQ(cell.in_reg(mm::kInAlarmCode), mm::kAlarmEstop);
  cell.coil(mm::kCoilSimEstop, false);
  cell.coil(mm::kCoilAlarmReset, true);  // e-stop cleared, heartbeat still missing
  EXPECT_EQ(cell.in_reg(mm::kInAlarmCode), mm::kAlarmHeartbeat);
  EXPECT_TRUE(cell.input(mm::kInputAlarmLatched));
}

TEST(Plc, MailboxDecodesABlock) {
  PlcCell cell;
  EXPECT_FALSE(cell.plc.pending_block());
  cell.submit(1, "G1 X10.5 Y-3 F1200");  // odd length: the last character in a high byte
  auto block = cell.plc.pending_block();
  ASSERT_TRUE(block);
  EXPECT_EQ(block->seq, 1);
  EXPECT_EQ(block->text, "G1 X10.5 Y-3 F1200");
  EXPECT_EQ(cell.in_reg(mm::kInMailboxAck), 0);
  cell.plc.accept_block(1);
  EXPECT_FALSE(cell.plc.pending_block());
  EXPECT_EQ(cell.in_reg(mm::kInMailboxAck), 1);

  cell.hold(mm::kHoldMailboxSeq, 1);  // same number again: nothing
  EXPECT_FALSE(cell.plc.pending_block());

  const std::string longest(200, 'X');
  cell.submit(2, longest);
  ASSERT_TRUE(cell.plc.pending_block());
  EXPECT_EQ(cell.plc.pending_block()->text, longest);
  cell.plc.accept_block(3);  // not the pending one: ignored
  EXPECT_TRUE(cell.plc.pending_block());
  cell.plc.accept_block(2);
  EXPECT_EQ(cell.in_reg(mm::kInMailboxAck), 2);
  EXPECT_EQ(cell.plc.alarm_code(), mm::kAlarmNone);

  cell.submit(3, "");  // an empty block is a block
  ASSERT_TRUE(cell.plc.pending_block());
  EXPECT_EQ(cell.plc.pending_block()->text, "");
}

TEST(Plc, MailboxOverrunLatchesAndKeepsTheFirstBlock) {
  PlcCell cell;
  cell.submit(1, "G0 X1");
  cell.submit(2, "G0 X2");
  EXPECT_EQ(cell.plc.alarm_code(), mm::kAlarmMailboxOverrun);
  ASSERT_TRUE(cell.plc.pending_block());
  EXPECT_EQ(cell.plc.pending_block()->seq, 1);
  EXPECT_EQ(cell.plc.pending_block()->text, "G0 X1");
  cell.coil(mm::kCoilAlarmReset, true);  // no lasting cause
  EXPECT_EQ(cell.plc.alarm_code(), mm::kAlarmNone);
}

TEST(Plc, MailboxRefusesBadBlocks) {
  PlcCell cell;
  cell.r().holding[mm::kHoldMailboxLength] = 201;
  cell.hold(mm::kHoldMailboxSeq, 1);
  EXPECT_FALSE(cell.plc.pending_block());
  EXPECT_EQ(cell.plc.alarm_code(), mm::kAlarmMailboxBadBlock);
  cell.coil(mm::kCoilAlarmReset, true);

  cell.submit(2, "G0 X1\nG0 X2");  // two lines in one block
  EXPECT_FALSE(cell.plc.pending_block());
  EXPECT_EQ(cell.plc.alarm_code(), mm::kAlarmMailboxBadBlock);
  cell.coil(mm::kCoilAlarmReset, true);

  cell.submit(3, "G0 Q5");
  ASSERT_TRUE(cell.plc.pending_block());
  cell.plc.refuse_block(3);  // the CNC did not like it
  EXPECT_FALSE(cell.plc.pending_block());
  EXPECT_EQ(cell.plc.alarm_code(), mm::kAlarmMailboxBadBlock);
  EXPECT_EQ(cell.in_reg(mm::kInMailboxAck), 0);
}

std::int32_t read_i32(PlcCell& cell, int high) {
  return static_cast<std::int32_t>((std::uint32_t{cell.in_reg(high)} << 16) | cell.in_reg(high + 1));
}

TEST(Plc, SnapshotEncoding) {
  PlcCell cell;
  cell.cnc.state = 1;
  cell.cnc.executed_blocks = 70000;  // > 16 bits
  cell.cnc.position[0] = 1234.5674;
  cell.cnc.position[1] = -0.001;
  cell.cnc.position[2] = -250.25;
  cell.cnc.position[3] = -45.0;
  cell.cnc.position[4] = 359.9996;
  cell.cnc.jet_request = true;
  cell.cnc.free_blocks = 17;
  cell.plc.tick(0.5, cell.cnc);
  EXPECT_EQ(cell.in_reg(mm::kInCncState), 1);
  EXPECT_EQ(cell.in_reg(mm::kInExecutedHigh), 1);
  EXPECT_EQ(cell.in_reg(mm::kInExecutedLow), 70000 - 65536);
  EXPECT_EQ(read_i32(cell, mm::kInPositionXHigh), 1234567);
  EXPECT_EQ(read_i32(cell, mm::kInPositionYHigh), -1);
  EXPECT_EQ(cell.in_reg(mm::kInPositionYHigh), 0xFFFF);  // two's complement, high word first
  EXPECT_EQ(cell.in_reg(mm::kInPositionYLow), 0xFFFF);
  EXPECT_EQ(read_i32(cell, mm::kInPositionZHigh), -250250);
  EXPECT_EQ(read_i32(cell, mm::kInPositionAHigh), -45000);
  EXPECT_EQ(read_i32(cell, mm::kInPositionCHigh), 360000);
  EXPECT_TRUE(cell.input(mm::kInputCncJetRequest));
  EXPECT_EQ(cell.in_reg(mm::kInMailboxFree), 17);

  cell.cnc.position[0] = 1e7;  // 10 km: clamped, not wrapped
  cell.cnc.free_blocks = 100000;
  cell.plc.tick(0.6, cell.cnc);
  EXPECT_EQ(read_i32(cell, mm::kInPositionXHigh), 2147483647);
  EXPECT_EQ(cell.in_reg(mm::kInMailboxFree), 65535);
}

TEST(Plc, CncButtonsArePushButtonsTakenOnce) {
  PlcCell cell;
  cell.coil(mm::kCoilCncFeedHold, true);
  EXPECT_EQ(cell.r().coils[mm::kCoilCncFeedHold], 0) << "the PLC releases the button at once";
  cell.run_to(0.1);  // a scan in between does not lose the press
  auto pressed = cell.plc.take_cnc_buttons();
  EXPECT_TRUE(pressed.feed_hold);
  EXPECT_FALSE(pressed.cycle_start);
  EXPECT_FALSE(pressed.reset);
  EXPECT_FALSE(cell.plc.take_cnc_buttons().any()) << "a press acts once";

  cell.r().coils[mm::kCoilCncCycleStart] = 1;
  cell.r().coils[mm::kCoilCncReset] = 1;
  cell.plc.after_client_write(cell.now);  // one FC15 write pressing two buttons
  pressed = cell.plc.take_cnc_buttons();
  EXPECT_TRUE(pressed.cycle_start);
  EXPECT_TRUE(pressed.reset);
  EXPECT_FALSE(pressed.feed_hold);
  EXPECT_EQ(cell.r().coils[mm::kCoilCncCycleStart], 0);
  EXPECT_EQ(cell.r().coils[mm::kCoilCncReset], 0);
}

// Two writes in one scan, hold then reset: the reset machine must not come back held (a held
// drip feed would then hold its next program's bytes for ever).
TEST(Plc, ResetSpendsAHoldPressedBeforeItInTheSameScan) {
  PlcCell cell;
  cell.coil(mm::kCoilCncFeedHold, true);
  cell.coil(mm::kCoilCncReset, true);
  auto pressed = cell.plc.take_cnc_buttons();
  EXPECT_TRUE(pressed.reset);
  EXPECT_FALSE(pressed.feed_hold);
  // The other order holds the machine after its reset.
  cell.coil(mm::kCoilCncReset, true);
  cell.coil(mm::kCoilCncFeedHold, true);
  pressed = cell.plc.take_cnc_buttons();
  EXPECT_TRUE(pressed.reset);
  EXPECT_TRUE(pressed.feed_hold);
}

}  // namespace
}  // namespace lamina::sim
