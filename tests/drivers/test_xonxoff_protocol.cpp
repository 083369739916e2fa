// The XON/XOFF drip feed, scripted as a Fanuc remote buffer throttles it (DC3/DC1, then
// SYN or NAK after a DC3).
#include <gtest/gtest.h>

#include <random>
#include <string>

#include "lamina/drivers/line_protocol.hpp"
#include "protocol_script.hpp"

namespace lamina::drivers {
namespace {

using namespace script;

constexpr char kDc1 = 0x11, kDc3 = 0x13, kNak = 0x15, kSyn = 0x16;

TEST(XonXoffProtocol, FramesTheProgramUnlessItIsFramed) {
  auto p = make_xonxoff_protocol({.chunk_bytes = 1000});
  EXPECT_TRUE(p->handshake_done());
  EXPECT_EQ(p->handshake(), "");
  p->load(LineSpan{{"O1000", "G1X1\r", "M30"}, 0});
  EXPECT_EQ(p->take_sendable(), "%\nO1000\nG1X1\nM30\n%\n");
  EXPECT_TRUE(p->finished());
  p->load(LineSpan{{"%", "G1X1", "%"}, 0});
  EXPECT_EQ(p->take_sendable(), "%\nG1X1\n%\n");
  auto unframed = make_xonxoff_protocol({.chunk_bytes = 1000, .send_percent_frame = false});
  unframed->load(LineSpan{{"G1X1"}, 0});
  EXPECT_EQ(unframed->take_sendable(), "G1X1\n");
}

TEST(XonXoffProtocol, TakeSendableKeepsToTheByteBudget) {
  auto p = make_xonxoff_protocol({.chunk_bytes = 10});
  p->load(LineSpan{{"O1000", "G1X1", "M30"}, 0});
  EXPECT_EQ(p->take_sendable(0), "");
  EXPECT_EQ(p->take_sendable(3), "%\nO") << "a byte stream: the budget may split a line";
  EXPECT_EQ(p->take_sendable(100), "1000\nG1X1\n") << "the chunk bounds it";
  EXPECT_EQ(p->take_sendable(100), "M30\n%\n");
  EXPECT_EQ(p->take_sendable(100), "");
}

TEST(XonXoffProtocol, Dc3StopsAtOnceDc1ResumesAtTheNextByte) {
  constexpr std::size_t kChunk = 7;
  auto p = make_xonxoff_protocol({.chunk_bytes = kChunk});
  const auto span = program(60, 23);
  p->load(span);
  std::string expected = "%\n";
  for (const auto& l : span.lines) expected += l + "\n";
  expected += "%\n";

  std::string wire;
  std::mt19937 rng(11);
  for (int round = 0; !p->finished(); ++round) {
    ASSERT_LT(round, 10000);
    const std::string chunk = p->take_sendable();
    ASSERT_LE(chunk.size(), kChunk);
    wire += chunk;
    if (rng() % 3 == 0) {
      p->on_received(std::string(1, kDc3));
      for (int i = 0; i < 3; ++i) ASSERT_EQ(p->take_sendable(), "") << "bytes after DC3";
      p->on_received(std::string(1, kDc1));
    }
  }
  EXPECT_EQ(wire, expected);  // byte for byte: nothing skipped, nothing repeated
  EXPECT_EQ(p->lines_accepted(), 60u);
}

TEST(XonXoffProtocol, LineIsAcceptedWhenItsLfIsWritten) {
  auto p = make_xonxoff_protocol({.chunk_bytes = 4});
  p->load(LineSpan{{"G1X1", "M30"}, 20});
  EXPECT_EQ(p->take_sendable(), "%\nG1");
  EXPECT_EQ(p->lines_accepted(), 0u);
  EXPECT_EQ(p->take_sendable(), "X1\nM");
  EXPECT_EQ(p->lines_accepted(), 1u);
  const auto accepted = only<LineAccepted>(p->on_received(""));  // delivered with the next read
  ASSERT_EQ(accepted.size(), 1u);
  EXPECT_EQ(accepted[0].index, 20u);
  EXPECT_EQ(p->take_sendable(), "30\n%");
  EXPECT_EQ(p->lines_accepted(), 2u);
  EXPECT_FALSE(p->finished()) << "the closing % is still to go";
  EXPECT_EQ(p->take_sendable(), "\n");
  EXPECT_TRUE(p->finished());
  // A chunk that stops just before the LF: the line is not written yet.
  auto q = make_xonxoff_protocol({.chunk_bytes = 6});
  q->load(LineSpan{{"G1X1"}, 0});
  EXPECT_EQ(q->take_sendable(), "%\nG1X1");
  EXPECT_EQ(q->lines_accepted(), 0u);
  EXPECT_EQ(q->take_sendable(), "\n%\n");
  EXPECT_EQ(q->lines_accepted(), 1u);
}

TEST(XonXoffProtocol, SynAfterDc3IsAResetAndStops) {
  auto p = make_xonxoff_protocol({.chunk_bytes = 8});
  p->load(program(20, 10));
  p->take_sendable();
  auto events = p->on_received(std::string{kDc3, kSyn});
  const auto resets = only<ControllerReset>(events);
  ASSERT_EQ(resets.size(), 1u);
  EXPECT_EQ(resets[0].text.find("without"), std::string::npos);
  p->on_received(std::string(1, kDc1));
  EXPECT_EQ(p->take_sendable(), "") << "a reset stops the job for good";
}

TEST(XonXoffProtocol, NakAfterDc3IsAnAlarmAndStops) {
  auto p = make_xonxoff_protocol({.chunk_bytes = 8});
  p->load(program(20, 10));
  p->take_sendable();
  EXPECT_TRUE(p->on_received(std::string(1, kDc3)).empty());
  const auto alarms = only<ControllerAlarm>(p->on_received(std::string(1, kNak)));  // in its own read
  ASSERT_EQ(alarms.size(), 1u);
  EXPECT_NE(alarms[0].meaning.find("NAK"), std::string::npos);
  p->on_received(std::string(1, kDc1));
  EXPECT_EQ(p->take_sendable(), "");
}

TEST(XonXoffProtocol, NoRealtimeBytes) {
  auto p = make_xonxoff_protocol();
  for (auto c : {RealtimeCommand::status, RealtimeCommand::feed_hold, RealtimeCommand::resume, RealtimeCommand::reset})
    EXPECT_EQ(p->realtime(c), "");
  EXPECT_EQ(p->clear_error_lock(), "");
  EXPECT_EQ(p->name(), "xonxoff");
}

}  // namespace
}  // namespace lamina::drivers
