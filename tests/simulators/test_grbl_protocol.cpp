// The grbl personality against a real Machine, byte by byte on a simulated clock.
#include <gtest/gtest.h>

#include <regex>
#include <string>

#include "grbl_protocol.hpp"
#include "protocol_harness.hpp"

namespace lamina::sim {
namespace {

using test::count_of;
using test::ProtocolHarness;

const std::string kBanner = "\r\nGrblHAL 1.1f ['$' or '$HELP' for help]\r\n";
// A 1024-byte grblHAL ring holds 1023 bytes (serialRxFree: (RX_BUFFER_SIZE - 1) - count).
constexpr std::size_t kRxFree = 1023;

struct Grbl : ProtocolHarness {
  explicit Grbl(MachineConfig config = {}, GrblParams params = {}) : ProtocolHarness(std::move(config)) {
    protocol = make_grbl_protocol(machine, params);
    protocol->on_connect(now_s);
    take();  // the banner (checked in its own test)
  }
  std::string status() {
    send("?");
    return take();
  }
};

MachineConfig small_planner(std::size_t blocks) {
  MachineConfig c;
  c.planner_blocks = blocks;
  return c;
}

// Fields of one status report: state, MPos X, Bf blocks, Bf rx, Ln (or -1), feed.
struct Status {
  std::string state;
  double x = 0;
  int bf_blocks = -1, bf_rx = -1;
  long ln = -1;
  long feed = -1;
};
Status parse_status(const std::string& text) {
  static const std::regex re(
      R"(<([A-Za-z:0-9]+)\|MPos:(-?[0-9.]+),-?[0-9.]+,-?[0-9.]+,-?[0-9.]+,-?[0-9.]+\|Bf:([0-9]+),([0-9]+)(\|Ln:([0-9]+))?\|FS:([0-9]+),0(\|[^>]*)?>\r\n)");
  std::smatch m;
  Status s;
  if (!std::regex_search(text, m, re)) {
    ADD_FAILURE() << "no status report in: " << text;
    return s;
  }
  s.state = m[1];
  s.x = std::stod(m[2]);
  s.bf_blocks = std::stoi(m[3]);
  s.bf_rx = std::stoi(m[4]);
  if (m[6].matched) s.ln = std::stol(m[6]);
  s.feed = std::stol(m[7]);
  return s;
}

TEST(GrblProtocol, BannerOnConnectAndAfterReset) {
  Machine machine{MachineConfig{}};
  auto proto = make_grbl_protocol(machine, {});
  proto->on_connect(0);
  EXPECT_EQ(proto->take_output(), kBanner);
  proto->on_byte(0x18, 0.1);
  EXPECT_EQ(proto->take_output(), kBanner);  // idle: no ALARM:3
}

TEST(GrblProtocol, OkPerLineAndCrLfIsOneEndOfLine) {
  Grbl g;
  g.send("G21\nG90\r\nG1 X10 F600\r");
  g.send("\n");  // the LF of the CR LF: no second ok
  EXPECT_EQ(g.take(), "ok\r\nok\r\nok\r\n");
  EXPECT_EQ(g.protocol->counters().lines_received, 3u);
  EXPECT_EQ(g.protocol->counters().oks_sent, 3u);
  g.send("\n\n");  // two real empty lines: two oks (the sync idiom)
  EXPECT_EQ(g.take(), "ok\r\nok\r\n");
}

TEST(GrblProtocol, ErrorThenLockUntilEmptyLine) {
  Grbl g;
  g.send("G0 X1 B5\n");  // no B axis on an XYZAC machine: an unused word
  EXPECT_EQ(g.take(), "error:36\r\n");
  const auto accepted = g.machine.accepted_blocks();
  g.send("G0 X5\nG0 X6\n");
  // grblHAL repeats the error for G-code lines after an error: nothing reaches the planner.
  EXPECT_EQ(g.take(), "error:36\r\nerror:36\r\n");
  EXPECT_EQ(g.machine.accepted_blocks(), accepted);
  g.send("\nG0 X5\n");
  EXPECT_EQ(g.take(), "ok\r\nok\r\n");
  EXPECT_EQ(g.machine.accepted_blocks(), accepted + 1);
  EXPECT_EQ(g.protocol->counters().errors_sent, 3u);
}

TEST(GrblProtocol, ErrorLockClearedByDollarCommand) {
  Grbl g;
  g.send("G1 X1 F1.2.3\n");
  const std::string first = g.take();
  ASSERT_TRUE(first.starts_with("error:")) << first;
  g.send("G0 X5\n");
  EXPECT_EQ(g.take(), first);
  g.send("$G\nG0 X5\n");
  const std::string out = g.take();
  EXPECT_TRUE(out.starts_with("[GC:")) << out;
  EXPECT_TRUE(out.ends_with("ok\r\nok\r\n")) << out;
}

TEST(GrblProtocol, ErrorLockClearedByReset) {
  Grbl g;
  g.send("G0 X1 B5\nG0 X2\n");
  EXPECT_EQ(g.take(), "error:36\r\nerror:36\r\n");
  g.send("\x18");
  EXPECT_EQ(g.take(), kBanner);
  g.send("G0 X2\n");
  EXPECT_EQ(g.take(), "ok\r\n");
}

TEST(GrblProtocol, SoftLimitAlarmThenErrorNineUntilUnlock) {
  Grbl g;
  g.send("G0 X5000\n");
  const std::string out = g.take();
  EXPECT_NE(out.find("ALARM:2\r\n"), std::string::npos) << out;
  EXPECT_NE(out.find("error:10\r\n"), std::string::npos) << out;
  EXPECT_LT(out.find("ALARM:2"), out.find("error:10"));
  EXPECT_EQ(parse_status(g.status()).state, "Alarm");
  g.send("G0 X1\n");
  EXPECT_EQ(g.take(), "error:9\r\n");
  g.send("$X\n");
  EXPECT_EQ(g.take(), "[MSG:Caution: Unlocked]\r\nok\r\n");
  g.send("G0 X1\n");
  EXPECT_EQ(g.take(), "ok\r\n");
  // The alarm is announced once, not at every poll.
  g.run_for(0.5);
  EXPECT_EQ(count_of(g.take(), "ALARM"), 0);
}

TEST(GrblProtocol, UnlockRefusedWhileEstopHeld) {
  Grbl g;
  g.machine.set_estop(true, g.now_s);
  g.tick();
  EXPECT_EQ(g.take(), "ALARM:10\r\n");
  g.send("$X\n");
  EXPECT_EQ(g.take(), "error:50\r\n");
  g.machine.set_estop(false, g.now_s);
  g.send("$X\n");
  EXPECT_EQ(g.take(), "[MSG:Caution: Unlocked]\r\nok\r\n");
}

TEST(GrblProtocol, UnknownDollarCommandIsErrorThree) {
  Grbl g;
  g.send("$Q\n");
  EXPECT_EQ(g.take(), "error:3\r\n");
}

TEST(GrblProtocol, StatusReportFollowsTheMotion) {
  Grbl g;
  Status idle = parse_status(g.status());
  EXPECT_EQ(idle.state, "Idle");
  EXPECT_EQ(idle.bf_blocks, 100);
  EXPECT_EQ(idle.bf_rx, static_cast<int>(kRxFree));
  EXPECT_EQ(idle.ln, -1);
  EXPECT_EQ(idle.feed, 0);

  g.send("N10 G1 X100 F6000\n");  // 100 mm at 100 mm/s: one second
  EXPECT_EQ(g.take(), "ok\r\n");
  g.run_for(0.3);
  const Status a = parse_status(g.status());
  g.run_for(0.3);
  const Status b = parse_status(g.status());
  EXPECT_EQ(a.state, "Run");
  EXPECT_EQ(a.ln, 10);
  EXPECT_EQ(a.feed, 6000);
  EXPECT_EQ(a.bf_blocks, static_cast<int>(g.machine.free_blocks()));
  EXPECT_LT(a.bf_blocks, 100);
  EXPECT_GT(a.x, 0.0);
  EXPECT_GT(b.x, a.x);  // MPos moves as time advances
  EXPECT_LT(b.x, 100.0);

  g.send_burst("G1 X");  // half a line in the receive buffer shows in Bf
  EXPECT_EQ(parse_status(g.status()).bf_rx, static_cast<int>(kRxFree) - 4);
  g.send("1\n");
  g.run_for(2.0);
  const Status done = parse_status(g.status());
  EXPECT_EQ(done.state, "Idle");
  EXPECT_NEAR(done.x, 1.0, 1e-9);
  EXPECT_EQ(done.ln, -1);
  EXPECT_EQ(done.bf_blocks, 100);
}

TEST(GrblProtocol, FeedHoldDeceleratesThenHoldsAndResumes) {
  Grbl g;
  g.send("G1 X200 F6000\n");
  g.run_for(0.5);
  g.send("!");
  EXPECT_EQ(parse_status(g.status()).state, "Hold:1");
  g.run_for(1.0);  // 100 mm/s at 500 mm/s² stops in 0.2 s
  const Status held = parse_status(g.status());
  EXPECT_EQ(held.state, "Hold:0");
  g.run_for(0.5);
  EXPECT_EQ(parse_status(g.status()).x, held.x);  // not moving while held
  g.send("~");
  g.run_for(0.1);
  EXPECT_EQ(parse_status(g.status()).state, "Run");
  g.run_for(5.0);
  const Status done = parse_status(g.status());
  EXPECT_EQ(done.state, "Idle");
  EXPECT_NEAR(done.x, 200.0, 1e-9);
}

TEST(GrblProtocol, RealTimeByteInsideALineDoesNotCorruptIt) {
  Grbl g;
  g.send("G1 X1?0 F6!~00\n");
  const std::string out = g.take();
  EXPECT_EQ(count_of(out, "<"), 1) << out;
  EXPECT_TRUE(out.ends_with("ok\r\n")) << out;
  g.run_for(1.0);
  const auto lines = g.executed_lines();
  ASSERT_FALSE(lines.empty());
  EXPECT_EQ(lines.back(), "G1 X10 F600");
}

TEST(GrblProtocol, ReceiveBufferOverflowLosesBytes) {
  GrblParams params;
  params.rx_buffer_bytes = 128;
  Grbl g({}, params);
  // A client that ignores the buffer: 200 bytes arrive faster than lines are taken.
  const std::string line = "G1 X1 F600\n";  // 11 bytes
  std::string burst;
  while (burst.size() < 200) burst += line;
  g.send_burst(burst);
  EXPECT_EQ(g.protocol->rx_free(), 0u);
  EXPECT_EQ(g.protocol->counters().bytes_received, 127u);  // the ring keeps one slot free
  EXPECT_EQ(g.protocol->counters().bytes_dropped, burst.size() - 127);
  // Real-time bytes still work with the buffer full: they never enter it.
  g.send_burst("?");
  EXPECT_EQ(parse_status(g.protocol->take_output()).bf_rx, 0);
  g.tick();
  // 11 whole lines fit in 127 bytes; the 12th is cut and joins what comes next.
  EXPECT_EQ(count_of(g.take(), "ok"), 11);
}

TEST(GrblProtocol, FullPlannerBackPressuresTheReceiveBuffer) {
  Grbl g(small_planner(3));
  std::string program;
  for (int i = 1; i <= 8; ++i) program += "G1 X" + std::to_string(i * 10) + " F600\n";  // 1 s each
  g.send(program);
  const int first = count_of(g.take(), "ok");
  EXPECT_GE(first, 3);
  EXPECT_LT(first, 8);
  EXPECT_EQ(static_cast<std::uint64_t>(first), g.machine.accepted_blocks());
  EXPECT_LT(g.protocol->rx_free(), kRxFree);  // the rest waits in the receive buffer
  g.run_for(20.0);
  EXPECT_EQ(first + count_of(g.take(), "ok"), 8);
  EXPECT_EQ(g.protocol->rx_free(), kRxFree);
}

// grblHAL's planner sync: M3 (jet on) is answered only when the motion before it is done, and
// the lines behind it wait with it; the jet turns on with the machine standing still.
TEST(GrblProtocol, AJetMCodeWaitsForTheMotionBeforeIt) {
  Grbl g(MachineConfig{});
  g.send("G1X10F600\nM3\nG1X20\nM5\nM30\n");  // each move takes 1 s
  EXPECT_EQ(count_of(g.take(), "ok"), 1) << "M3 and the lines behind it wait in the receive buffer";
  g.run_for(0.9);
  EXPECT_EQ(count_of(g.take(), "ok"), 0);
  g.run_for(0.2);
  EXPECT_EQ(count_of(g.take(), "ok"), 2) << "M3 and the move behind it, once the first move is done";
  g.run_for(2.0);
  EXPECT_EQ(count_of(g.take(), "ok"), 2) << "M5 and M30 after the second move";
  const auto events = g.machine.take_events();
  std::vector<ExecutedBlock> done;
  for (const auto& e : events)
    if (const auto* b = std::get_if<ExecutedBlock>(&e)) done.push_back(*b);
  ASSERT_EQ(done.size(), 5u);
  EXPECT_GE(done[1].t_start_s, done[0].t_end_s - 1e-9) << "the jet turns on after the move";
  EXPECT_GE(done[3].t_start_s, done[2].t_end_s - 1e-9) << "and off after the next";
  EXPECT_FALSE(done[0].jet);
  EXPECT_TRUE(done[2].jet);
  EXPECT_EQ(g.machine.starvation_count(), 0u) << "a sync is the program's own stop";
}

TEST(GrblProtocol, DropOkFaultLosesExactlyTheKthOk) {
  GrblParams params;
  params.faults.drop_ok_index = 2;
  Grbl g({}, params);
  g.send("G21\nG90\nG94\n");
  EXPECT_EQ(g.take(), "ok\r\nok\r\n");
  EXPECT_EQ(g.protocol->counters().oks_sent, 2u);
  EXPECT_EQ(g.protocol->counters().oks_dropped, 1u);
  EXPECT_EQ(g.machine.accepted_blocks(), 3u);  // the line itself was executed
}

TEST(GrblProtocol, StallStopsTakingLines) {
  Grbl g;
  g.protocol->set_stalled(true);
  g.send("G21\n");
  g.run_for(0.5);
  EXPECT_EQ(g.take(), "");
  EXPECT_EQ(g.protocol->rx_free(), kRxFree - 4);
  g.protocol->set_stalled(false);
  g.tick();
  EXPECT_EQ(g.take(), "ok\r\n");
  EXPECT_EQ(g.protocol->rx_free(), kRxFree);
}

TEST(GrblProtocol, ResetWhileMovingRaisesAlarmThree) {
  Grbl g;
  g.send("G1 X100 F600\nG1 X200\n");
  g.run_for(0.5);
  g.take();
  g.send_burst("G1 X3");  // a partial line is flushed by the reset
  g.send("\x18");
  EXPECT_EQ(g.take(), "ALARM:3\r\n" + kBanner + "[MSG:'$H'|'$X' to unlock]\r\n");
  EXPECT_EQ(g.machine.state(), MachineState::alarm);
  EXPECT_EQ(g.protocol->rx_free(), kRxFree);
  EXPECT_EQ(g.machine.queued_blocks(), 0u);
  g.send("G0 X1\n");
  EXPECT_EQ(g.take(), "error:9\r\n");
  g.protocol->external_reset(g.now_s);  // still in alarm, not moving: banner, no new ALARM:3
  EXPECT_EQ(g.take(), kBanner + "[MSG:'$H'|'$X' to unlock]\r\n");
}

TEST(GrblProtocol, BuildInfoCarriesPlannerRxAndAxes) {
  GrblParams params;
  params.rx_buffer_bytes = 256;
  Grbl g(small_planner(7), params);
  g.send("$I\n");
  const std::string out = g.take();
  EXPECT_TRUE(out.starts_with("[VER:1.1f.")) << out;
  EXPECT_NE(out.find("[OPT:VNL,7,256,5,0]\r\n"), std::string::npos) << out;
  EXPECT_NE(out.find("[AXS:5:XYZAC]\r\n"), std::string::npos) << out;
  EXPECT_TRUE(out.ends_with("]\r\nok\r\n")) << out;
}

TEST(GrblProtocol, ExtendedRealTimeBytesAndTopBitBytesStayOutOfTheBuffer) {
  Grbl g;
  g.send("G1 X100 F6000\n");
  g.run_for(0.2);
  g.take();
  g.send("\x84\xA5\xFF\x07");  // safety door (no door here), unknown, bell: all dropped
  EXPECT_EQ(g.protocol->rx_free(), kRxFree);
  EXPECT_EQ(g.protocol->counters().bytes_received, 14u);
  g.send("\x82");  // grblHAL's feed hold
  g.send("\x80");  // grblHAL's status report
  EXPECT_EQ(parse_status(g.take()).state, "Hold:1");
  g.run_for(1.0);
  g.send("\x81");  // grblHAL's cycle start
  g.run_for(0.1);
  EXPECT_EQ(parse_status(g.status()).state, "Run");
}

TEST(GrblProtocol, ParserStateShowsTheAcceptedModes) {
  Grbl g;
  g.send("$G\n");
  EXPECT_EQ(g.take(), "[GC:G0 G54 G17 G21 G90 G94 M5 M9 T0 F0 S0]\r\nok\r\n");
  g.send("G20 G91 G1 X0.1 F12\n$G\n");
  EXPECT_EQ(g.take(), "ok\r\n[GC:G1 G54 G17 G20 G91 G94 M5 M9 T0 F12 S0]\r\nok\r\n");
  g.run_for(1.0);  // 0.1 in at 12 in/min: done after 0.5 s, so the reset is not an abort
  g.send("\x18$G\n");  // reset: defaults again
  EXPECT_EQ(g.take(), kBanner + "[GC:G0 G54 G17 G21 G90 G94 M5 M9 T0 F0 S0]\r\nok\r\n");
}

TEST(GrblProtocol, OverlongLineIsErrorEleven) {
  Grbl g;
  g.send("G0 X1" + std::string(300, ' ') + "\n");  // spaces after the first character count
  EXPECT_EQ(g.take(), "error:11\r\n");
}

}  // namespace
}  // namespace lamina::sim
