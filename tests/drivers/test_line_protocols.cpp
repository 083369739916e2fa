// The Grbl character-counting and send-response protocols, scripted byte by byte as a
// grblHAL controller answers (sans-IO: no port, no clock).
#include <gtest/gtest.h>

#include <deque>
#include <random>
#include <string>

#include <fmt/format.h>

#include "lamina/drivers/line_protocol.hpp"
#include "protocol_script.hpp"

namespace lamina::drivers {
namespace {

using namespace script;

// A connected grbl protocol that learned `rx` bytes from [OPT:].
std::unique_ptr<LineProtocol> connected_grbl(int rx, GrblProtocolSettings settings = {}) {
  auto p = make_grbl_protocol(settings);
  EXPECT_EQ(p->handshake(), "$I\n");
  feed_bytewise(*p, "[VER:1.1f.20240501:]\r\n[OPT:VNL,35," + std::to_string(rx) + ",5,0]\r\n[AXS:5:XYZAC]\r\nok\r\n");
  EXPECT_TRUE(p->handshake_done());
  return p;
}

TEST(GrblProtocol, HandshakeLearnsBuildInfoAtItsOk) {
  auto p = make_grbl_protocol();
  EXPECT_FALSE(p->handshake_done());
  EXPECT_EQ(p->handshake(), "$I\n");
  auto before = feed_bytewise(*p, "[VER:1.1f.20240501:]\r\n[OPT:VNL,35,1024,5,0]\r\n[AXS:5:XYZAC]\r\n");
  EXPECT_TRUE(before.empty());
  EXPECT_FALSE(p->handshake_done());
  p->load(program(3, 10));
  EXPECT_EQ(p->take_sendable(), "") << "no program line before the handshake's ok";
  const auto info = only<ControllerInfo>(feed_bytewise(*p, "ok\r\n"));
  ASSERT_EQ(info.size(), 1u);
  EXPECT_TRUE(p->handshake_done());
  EXPECT_EQ(info[0].planner_blocks, 35);
  EXPECT_EQ(info[0].rx_buffer_bytes, 1024);
  EXPECT_EQ(info[0].axes, 5);
  EXPECT_EQ(info[0].axis_letters, "XYZAC");
  EXPECT_EQ(count_lines(p->take_sendable()), 3u);
}

// The pacer's budget: whole lines up to it, at least one line however long; the window still
// bounds the total. Without the budget a resume handed out a whole 1 KiB window at once, and a
// feed hold queued behind it waited 88 ms for the wire (bench/hold_latency).
TEST(GrblProtocol, TakeSendableKeepsToTheByteBudgetInWholeLines) {
  auto p = connected_grbl(1024);
  p->load(program(200, 10));  // 2000 bytes: more than the window
  const std::string first = p->take_sendable(25);
  EXPECT_LE(first.size(), 25u);
  EXPECT_GE(count_lines(first), 1u);
  EXPECT_EQ(first.back(), '\n') << "never half a line";
  const std::string one = p->take_sendable(1);
  EXPECT_EQ(count_lines(one), 1u) << "a line longer than the budget goes alone";
  std::size_t total = first.size() + one.size();
  for (std::string more; !(more = p->take_sendable(100)).empty();) {
    EXPECT_LE(more.size(), 100u);
    total += more.size();
  }
  EXPECT_LE(total, 1024u) << "the window still bounds what is in flight";
}

TEST(GrblProtocol, ResetDuringTheHandshakeNeedsItAgain) {
  // Opening a port resets many Grbl boards (DTR): the `$I` sent at once is lost in the boot.
  auto p = make_grbl_protocol();
  EXPECT_EQ(p->handshake(), "$I\n");
  EXPECT_EQ(only<ControllerReset>(feed_bytewise(*p, "\r\nGrblHAL 1.1f ['$' or '$HELP' for help]\r\n")).size(), 1u);
  EXPECT_FALSE(p->handshake_done());
  EXPECT_EQ(only<ProtocolViolation>(feed_bytewise(*p, "ok\r\n")).size(), 1u) << "the lost $I has no ok to come";
  EXPECT_EQ(p->handshake(), "$I\n");
  EXPECT_EQ(only<ControllerInfo>(feed_bytewise(*p, "[OPT:VNL,35,1024,5,0]\r\nok\r\n")).size(), 1u);
  EXPECT_TRUE(p->handshake_done());
}

TEST(GrblProtocol, AnOkBeforeTheBuildInfoIsAnEarlierHostsAndIgnored) {
  // laminad restarted while the controller drains the lines the dead daemon gave it: their
  // acks arrive after our `$I`. Only the ok that follows the build info ends the handshake.
  auto p = make_grbl_protocol();
  EXPECT_EQ(p->handshake(), "$I\n");
  EXPECT_TRUE(feed_bytewise(*p, "ok\r\nok\r\n[MSG:'$H'|'$X' to unlock]\r\nok\r\n").empty());
  EXPECT_FALSE(p->handshake_done());
  p->load(program(2, 10));
  EXPECT_EQ(p->take_sendable(), "");
  const auto info = only<ControllerInfo>(feed_bytewise(*p, "[VER:1.1f.20240501:]\r\n[OPT:VNL,35,1024,5,0]\r\nok\r\n"));
  ASSERT_EQ(info.size(), 1u);
  EXPECT_EQ(info[0].rx_buffer_bytes, 1024);
  EXPECT_EQ(count_lines(p->take_sendable()), 2u);
  // A controller without `$I` refuses it outright: that error ends the handshake too.
  auto old = make_grbl_protocol();
  old->handshake();
  EXPECT_EQ(only<ControllerInfo>(feed_bytewise(*old, "error:3\r\n")).size(), 1u);
  EXPECT_TRUE(old->handshake_done());
}

TEST(GrblProtocol, WindowComesFromOptUnlessConfigured) {
  // Learned 256: five 50-byte lines fit (250), a sixth would not.
  auto learned = connected_grbl(256);
  learned->load(program(10, 49));
  EXPECT_EQ(count_lines(learned->take_sendable()), 5u);
  // Configured 128 wins over the controller's 256.
  auto configured = connected_grbl(256, {.rx_buffer_bytes = 128});
  configured->load(program(10, 49));
  EXPECT_EQ(count_lines(configured->take_sendable()), 2u);
  // A Grbl whose [OPT:] has no rx size: classic 128.
  auto classic = make_grbl_protocol();
  classic->handshake();
  const auto info = only<ControllerInfo>(feed_bytewise(*classic, "[VER:1.1h.20190830:]\r\n[OPT:V,15]\r\nok\r\n"));
  ASSERT_EQ(info.size(), 1u);
  EXPECT_EQ(info[0].planner_blocks, 15);
  EXPECT_EQ(info[0].rx_buffer_bytes, 128);
}

TEST(GrblProtocol, WindowNeverExceeded) {
  constexpr std::size_t kRx = 128;
  auto p = connected_grbl(kRx);
  p->load(program(200, 49));  // 50 bytes with '\n': at most two in flight
  std::deque<std::size_t> controller;  // bytes of each line the controller holds unanswered
  std::mt19937 rng(7);
  std::size_t accepted = 0, most_lines = 0;
  while (accepted < 200) {
    std::string bytes = p->take_sendable();
    for (std::size_t start = 0; start < bytes.size();) {
      const auto end = bytes.find('\n', start);
      controller.push_back(end + 1 - start);
      start = end + 1;
    }
    std::size_t held = 0;
    for (auto b : controller) held += b;
    ASSERT_LE(held, kRx - 1) << "a ring of 128 bytes holds 127";
    most_lines = std::max(most_lines, controller.size());
    ASSERT_FALSE(controller.empty()) << "stalled with nothing in flight";
    const std::size_t answers = 1 + rng() % controller.size();  // answer some, in ok chunks
    std::string oks;
    for (std::size_t i = 0; i < answers; ++i, controller.pop_front()) oks += "ok\r\n";
    accepted += only<LineAccepted>(p->on_received(oks)).size();
  }
  EXPECT_EQ(most_lines, 2u);
  EXPECT_TRUE(p->finished());
  EXPECT_EQ(p->lines_accepted(), 200u);
}

// grblHAL's receive ring of N bytes holds N − 1 (Bf shows at most 1023 free of 1024): lines
// that add up to exactly N would lose their last byte, the '\n' that ends a line, and two
// lines would run as one.
TEST(GrblProtocol, WindowIsOneByteLessThanTheBuffer) {
  auto p = connected_grbl(128);
  p->load(program(4, 31));  // 32 bytes each with '\n': four make exactly 128
  EXPECT_EQ(count_lines(p->take_sendable()), 3u) << "96 bytes in flight, a fourth would fill all 128";
  EXPECT_EQ(only<LineAccepted>(p->on_received("ok\r\n")).size(), 1u);
  EXPECT_EQ(count_lines(p->take_sendable()), 1u);
}

TEST(GrblProtocol, OkSplitAcrossReadsCountsOnceWhenComplete) {
  auto p = connected_grbl(1024);
  p->load(program(2, 10, 40));
  EXPECT_EQ(count_lines(p->take_sendable()), 2u);
  EXPECT_TRUE(p->on_received("o").empty());
  EXPECT_TRUE(p->on_received("k\r").empty());
  const auto first = only<LineAccepted>(p->on_received("\nok"));
  ASSERT_EQ(first.size(), 1u);
  EXPECT_EQ(first[0].index, 40u);  // the program's numbering, not the span's
  const auto second = only<LineAccepted>(p->on_received("\n"));  // LF alone ends a line too
  ASSERT_EQ(second.size(), 1u);
  EXPECT_EQ(second[0].index, 41u);
  EXPECT_TRUE(p->finished());
}

TEST(GrblProtocol, ErrorMidStreamStopsAndTheLockedLinesAreNotNewFailures) {
  auto p = connected_grbl(128);
  p->load(program(10, 20, 100));  // 21 bytes each: six in flight (126)
  EXPECT_EQ(count_lines(p->take_sendable()), 6u);
  auto events = feed_bytewise(*p, "ok\r\nok\r\nerror:20\r\n");
  EXPECT_EQ(only<LineAccepted>(events).size(), 2u);
  const auto rejected = only<LineRejected>(events);
  ASSERT_EQ(rejected.size(), 1u);
  EXPECT_EQ(rejected[0].index, 102u);
  EXPECT_EQ(rejected[0].code, 20);
  EXPECT_NE(rejected[0].meaning.find("unsupported"), std::string::npos) << rejected[0].meaning;
  EXPECT_NE(rejected[0].meaning.find("(20)"), std::string::npos) << rejected[0].meaning;
  // Room in the window, but nothing more goes out.
  EXPECT_EQ(p->take_sendable(), "");
  EXPECT_EQ(p->clear_error_lock(), "\n");
  // grblHAL's lock refuses the three lines that were already in its buffer, then answers the
  // empty line: none of that is a new failure or a violation.
  events = feed_bytewise(*p, "error:20\r\nerror:20\r\nerror:20\r\nok\r\n");
  EXPECT_TRUE(events.empty()) << events.size() << " events";
  EXPECT_EQ(p->lines_accepted(), 2u);
  EXPECT_EQ(p->lines_sent(), 6u);
  EXPECT_FALSE(p->finished());
  EXPECT_EQ(p->take_sendable(), "");
  // Now nothing is in flight: a further ok is wrong.
  EXPECT_EQ(only<ProtocolViolation>(feed_bytewise(*p, "ok\r\n")).size(), 1u);
}

TEST(GrblProtocol, ErrorMeaningsNameTheCode) {
  std::vector<int> codes;
  for (int c = 1; c <= 39; ++c) codes.push_back(c);
  codes.insert(codes.end(), {45, 50, 79});
  for (const int code : codes) {
    auto p = connected_grbl(1024);
    p->load(program(1, 10));
    p->take_sendable();
    const auto rejected = only<LineRejected>(p->on_received(fmt::format("error:{}\r\n", code)));
    ASSERT_EQ(rejected.size(), 1u) << code;
    EXPECT_EQ(rejected[0].code, code);
    EXPECT_EQ(rejected[0].meaning.find("unknown"), std::string::npos) << rejected[0].meaning;
    EXPECT_NE(rejected[0].meaning.find(fmt::format("({})", code)), std::string::npos) << rejected[0].meaning;
  }
}

TEST(GrblProtocol, AlarmHalts) {
  auto p = connected_grbl(1024);
  p->load(program(10, 20));
  EXPECT_EQ(count_lines(p->take_sendable()), 10u);
  auto events = feed_bytewise(*p, "ok\r\nALARM:2\r\n[MSG:Reset to continue]\r\n");
  const auto alarms = only<ControllerAlarm>(events);
  ASSERT_EQ(alarms.size(), 1u);
  EXPECT_EQ(alarms[0].code, 2);
  EXPECT_NE(alarms[0].meaning.find("soft limit"), std::string::npos) << alarms[0].meaning;
  EXPECT_EQ(only<LineAccepted>(events).size(), 1u);
  // In alarm the controller refuses what it still holds (error:9): not a job failure of its own.
  events = feed_bytewise(*p, "error:9\r\nerror:9\r\n");
  EXPECT_TRUE(only<LineRejected>(events).empty());
  EXPECT_TRUE(only<ProtocolViolation>(events).empty());
  p->load(program(1, 10));  // a new span (after recovery) streams again
  EXPECT_EQ(count_lines(p->take_sendable()), 1u);
}

TEST(GrblProtocol, BannerIsAResetThatLosesTheLinesInFlight) {
  auto p = connected_grbl(1024);
  p->load(program(10, 20));
  p->take_sendable();
  auto events = feed_bytewise(*p, "ok\r\nGrblHAL 1.1f ['$' or '$HELP' for help]\r\n");
  const auto resets = only<ControllerReset>(events);
  ASSERT_EQ(resets.size(), 1u);
  EXPECT_EQ(resets[0].text, "GrblHAL 1.1f ['$' or '$HELP' for help]");
  EXPECT_EQ(p->lines_accepted(), 1u);
  EXPECT_EQ(p->take_sendable(), "");
  // The nine lines are gone with the reset: an ok now answers nothing.
  EXPECT_EQ(only<ProtocolViolation>(feed_bytewise(*p, "ok\r\n")).size(), 1u);
  EXPECT_EQ(only<ControllerReset>(p->on_received("Grbl 1.1h ['$' for help]\r\n")).size(), 1u);
}

TEST(GrblProtocol, UnexpectedOkAndGarbageAreViolations) {
  auto p = connected_grbl(1024);
  EXPECT_EQ(only<ProtocolViolation>(feed_bytewise(*p, "ok\r\n")).size(), 1u);
  EXPECT_EQ(only<ProtocolViolation>(feed_bytewise(*p, "error:2\r\n")).size(), 1u);
  EXPECT_EQ(only<ProtocolViolation>(feed_bytewise(*p, "o\x8bk\r\n")).size(), 1u);
  EXPECT_EQ(only<ProtocolViolation>(feed_bytewise(*p, "<Idle|MPos:1,x,3,4,5>\r\n")).size(), 1u);
}

TEST(GrblProtocol, PushMessagesIgnoredStatusReported) {
  auto p = connected_grbl(1024);
  p->load(program(1, 10));
  p->take_sendable();
  auto events = feed_bytewise(*p, "[MSG:Caution: Unlocked]\r\n[GC:G0 G54 G17 G21 G90 G94 M5 M9 T0 F0 S0]\r\n$0=10\r\n"
                                  "<Run|MPos:1.000,2.000,3.000,4.000,5.000|Bf:99,1013|Ln:7|FS:600,0>\r\nok\r\n");
  ASSERT_EQ(events.size(), 2u);
  const auto status = only<StatusReceived>(events);
  ASSERT_EQ(status.size(), 1u);
  EXPECT_EQ(status[0].status.state, ControllerState::run);
  EXPECT_EQ(status[0].status.line_number, 7);
  EXPECT_EQ(only<LineAccepted>(events).size(), 1u);
}

TEST(GrblProtocol, RealtimeBytesAndUnlock) {
  auto p = make_grbl_protocol();
  EXPECT_EQ(p->realtime(RealtimeCommand::status), "?");
  EXPECT_EQ(p->realtime(RealtimeCommand::feed_hold), "!");
  EXPECT_EQ(p->realtime(RealtimeCommand::resume), "~");
  EXPECT_EQ(p->realtime(RealtimeCommand::reset), "\x18");
  EXPECT_EQ(p->unlock_lines(), std::vector<std::string>{"$X"});
  EXPECT_EQ(p->name(), "grbl");
}

TEST(GrblProtocol, ProgramLinesGoOutVerbatimButForTrailingCr) {
  auto p = connected_grbl(1024);
  p->load(LineSpan{{"G1 X1 (cut)\r", " M3 ; jet"}, 0});
  EXPECT_EQ(p->take_sendable(), "G1 X1 (cut)\n M3 ; jet\n");
}

TEST(GrblProtocol, OperatorHaltKeepsCountingTheLinesInFlight) {
  auto p = connected_grbl(1024);
  p->load(program(10, 20));
  EXPECT_EQ(count_lines(p->take_sendable()), 10u);
  p->halt();
  EXPECT_EQ(p->take_sendable(), "");
  EXPECT_EQ(only<LineAccepted>(p->on_received("ok\r\nok\r\n")).size(), 2u);
  // A new span while eight answers are due: they belong to the old span, and fill the window.
  p->load(program(1, 10, 50));
  EXPECT_EQ(count_lines(p->take_sendable()), 1u);
  std::string eight_oks;
  for (int i = 0; i < 8; ++i) eight_oks += "ok\r\n";
  EXPECT_TRUE(p->on_received(eight_oks).empty());
  const auto accepted = only<LineAccepted>(p->on_received("ok\r\n"));
  ASSERT_EQ(accepted.size(), 1u);
  EXPECT_EQ(accepted[0].index, 50u);
  EXPECT_TRUE(p->finished());
}

TEST(SendResponseProtocol, OneLineInFlight) {
  auto p = make_send_response_protocol();
  EXPECT_EQ(p->handshake(), "");
  EXPECT_TRUE(p->handshake_done());
  EXPECT_EQ(p->name(), "send-response");
  p->load(program(3, 5));
  EXPECT_EQ(count_lines(p->take_sendable()), 1u);
  EXPECT_EQ(p->take_sendable(), "");
  EXPECT_EQ(only<LineAccepted>(feed_bytewise(*p, "ok\r\n")).size(), 1u);
  EXPECT_EQ(count_lines(p->take_sendable()), 1u);
  EXPECT_EQ(p->take_sendable(), "");
  const auto rejected = only<LineRejected>(feed_bytewise(*p, "error:33\r\n"));
  ASSERT_EQ(rejected.size(), 1u);
  EXPECT_EQ(rejected[0].index, 1u);
  EXPECT_EQ(p->take_sendable(), "");
  EXPECT_EQ(p->clear_error_lock(), "\n");
  EXPECT_TRUE(feed_bytewise(*p, "ok\r\n").empty());  // the empty line's answer
}

}  // namespace
}  // namespace lamina::drivers
