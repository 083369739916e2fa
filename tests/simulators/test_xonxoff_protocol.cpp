// The xonxoff (Fanuc protocol B drip feed) personality against a real Machine.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "protocol_harness.hpp"
#include "xonxoff_protocol.hpp"

namespace lamina::sim {
namespace {

using test::count_of;
using test::ProtocolHarness;

const std::string kDc1 = "\x11";
const std::string kDc3 = "\x13";
const std::string kNak = "\x15";
const std::string kSyn = "\x16";

XonXoffParams small_buffer() {
  XonXoffParams p;
  p.buffer_bytes = 256;
  p.high_water_bytes = 192;
  p.low_water_bytes = 64;
  p.overrun_margin_bytes = 16;
  return p;
}

struct XonXoff : ProtocolHarness {
  explicit XonXoff(XonXoffParams params = small_buffer(), MachineConfig config = {})
      : ProtocolHarness(std::move(config)) {
    protocol = make_xonxoff_protocol(machine, params);
  }
};

// `n` short blocks, 11 bytes each ("G1 X1 F600\n" style, alternating X so every one moves).
std::string blocks(int n) {
  std::string s;
  for (int i = 0; i < n; ++i) s += (i % 2 == 0) ? "G1 X1 F600\n" : "G1 X2 F600\n";
  return s;
}

TEST(XonXoffProtocol, ConnectSaysReadyWithDc1) {
  XonXoff x;
  x.protocol->on_connect(0);
  EXPECT_EQ(x.take(), kDc1);
}

TEST(XonXoffProtocol, ProgramRunsLineForLineAndLeaderIsIgnored) {
  XonXoff x;
  x.send("G0 X500\r\n");  // before the first %: tape leader, ignored
  const std::vector<std::string> program{"(O1000 DEMO)", "G21 G90", "G1 X10 F600", "", "G1 Y5", "M30"};
  std::string text = "%\r\n";
  for (const auto& line : program) text += line + "\r\n";
  text += "%";
  x.send(text);
  x.run_for(5.0);
  EXPECT_EQ(x.executed_lines(), program);
  EXPECT_EQ(x.protocol->counters().lines_received, program.size());
  EXPECT_EQ(x.take(), "");  // no per-line acks, no DC3 for a short program
  // After the closing % it waits for the next one: this is leader again.
  x.send("G0 X700\n");
  x.run_for(1.0);
  EXPECT_EQ(x.machine.accepted_blocks(), program.size());
}

TEST(XonXoffProtocol, Dc3AtHighWaterAndDc1BelowLowWater) {
  XonXoff x;
  x.protocol->set_stalled(true);  // nothing is taken: the buffer only fills
  x.send("%\n");
  const std::string data = blocks(20);  // 220 bytes
  std::size_t dc3_after = 0;
  for (std::size_t i = 0; i < data.size() && dc3_after == 0; ++i) {
    x.send(std::string_view(&data[i], 1));
    if (x.take().find(kDc3) != std::string::npos) dc3_after = i + 1;
  }
  // The buffer holds "%\n" too: DC3 when it first holds more than 192 bytes.
  EXPECT_EQ(dc3_after + 2, 193u);
  x.protocol->set_stalled(false);
  x.tick();
  EXPECT_EQ(x.take(), kDc1);  // the 100-block planner takes every line: buffer below 64
  EXPECT_FALSE(x.machine.alarm().has_value());
}

TEST(XonXoffProtocol, Dc1WaitsUntilTheMachineDrainsTheBuffer) {
  MachineConfig config;
  config.planner_blocks = 2;
  XonXoff x(small_buffer(), config);
  std::string slow;  // 10 bytes and 1 s (1 mm at 60 mm/min) per block
  for (int i = 0; i < 22; ++i) slow += (i % 2 == 0) ? "G1 X1 F60\n" : "G1 X2 F60\n";
  x.send("%\n" + slow);  // the planner takes only 2 at a time
  EXPECT_EQ(count_of(x.take(), kDc3), 1);
  x.run_for(3.0);
  EXPECT_EQ(x.take(), "");  // still above low water
  x.run_for(20.0);
  EXPECT_EQ(x.take(), kDc1);
  EXPECT_FALSE(x.machine.alarm().has_value());
}

TEST(XonXoffProtocol, OverrunBeyondMarginIsLostAndRaisesAlarm) {
  XonXoff x;
  x.protocol->set_stalled(true);
  const std::string data = "%\n" + blocks(30);  // 332 bytes, far past 192 + 16
  x.send(data);
  const std::string out = x.take();
  EXPECT_EQ(out, kDc3 + kDc3 + kNak);
  ASSERT_TRUE(x.machine.alarm().has_value());
  EXPECT_EQ(*x.machine.alarm(), GrblAlarm::buffer_overflow);
  const auto& c = x.protocol->counters();
  EXPECT_EQ(c.bytes_received, 193u + 16u);
  EXPECT_EQ(c.bytes_dropped, data.size() - c.bytes_received);
  EXPECT_EQ(x.protocol->rx_free(), 256u);  // flushed
}

TEST(XonXoffProtocol, MachineAlarmSendsDc3Nak) {
  XonXoff x;
  x.send("%\nG0 X5000\n");  // outside the soft limits
  EXPECT_EQ(x.take(), kDc3 + kNak);
  EXPECT_EQ(*x.machine.alarm(), GrblAlarm::soft_limit);
  x.run_for(1.0);
  EXPECT_EQ(x.take(), "");  // announced once
}

TEST(XonXoffProtocol, BadBlockStopsWithAnAlarm) {
  XonXoff x;
  x.send("%\nG1 X10 F600\nG1 X1 B5\nG1 X20\n");
  EXPECT_EQ(x.take(), kDc3 + kNak);
  EXPECT_EQ(*x.machine.alarm(), GrblAlarm::program_error);
  EXPECT_EQ(x.machine.accepted_blocks(), 1u);  // the block after the bad one never ran
}

TEST(XonXoffProtocol, ResetSendsDc3SynThenAcceptsANewProgram) {
  XonXoff x;
  x.send("%\nG1 X100 F600\nG1 X200\n");
  x.run_for(0.5);
  x.protocol->external_reset(x.now_s);
  x.tick();
  EXPECT_EQ(x.take(), kDc3 + kSyn + kDc1);
  EXPECT_FALSE(x.machine.alarm().has_value());  // a Fanuc reset is not an alarm
  EXPECT_EQ(x.machine.queued_blocks(), 0u);
  const auto before = x.machine.accepted_blocks();
  x.send("G1 X7\n%\nG1 X5 F600\n%");  // bytes before the new % are leader
  x.run_for(2.0);
  EXPECT_EQ(x.machine.accepted_blocks(), before + 1);
  EXPECT_EQ(x.executed_lines().back(), "G1 X5 F600");
}

TEST(XonXoffProtocol, ResetAfterAlarmClearsItAndSaysReady) {
  XonXoff x;
  x.send("%\nG0 X5000\n");
  EXPECT_EQ(x.take(), kDc3 + kNak);
  x.send("G0 X1\n");
  EXPECT_GT(x.protocol->counters().bytes_dropped, 0u);  // halted: input is lost
  x.protocol->external_reset(x.now_s);
  x.tick();
  EXPECT_EQ(x.take(), kDc3 + kSyn + kDc1);
  x.send("%\nG0 X1\n%");
  x.run_for(1.0);
  EXPECT_EQ(x.executed_lines().back(), "G0 X1");
}

TEST(XonXoffProtocol, EstopHaltsAndResetWaitsForItsRelease) {
  XonXoff x;
  x.send("%\nG1 X100 F600\n");
  x.run_for(0.2);
  x.machine.set_estop(true, x.now_s);
  x.tick();
  EXPECT_EQ(x.take(), kDc3 + kNak);
  x.protocol->external_reset(x.now_s);  // e-stop still pressed: no DC1
  x.run_for(0.5);
  EXPECT_EQ(x.take(), kDc3 + kSyn);
  EXPECT_TRUE(x.machine.alarm().has_value());
  x.machine.set_estop(false, x.now_s);
  x.protocol->external_reset(x.now_s);
  x.tick();
  EXPECT_EQ(x.take(), kDc3 + kSyn + kDc1);
  EXPECT_FALSE(x.machine.alarm().has_value());
}

}  // namespace
}  // namespace lamina::sim
