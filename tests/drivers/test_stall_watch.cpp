// The stall rule on its own (sans-IO, time as an argument): status reports scripted as a
// grblHAL sends them while it dwells, syncs, stalls or loses an answer.
#include <gtest/gtest.h>

#include "stall_watch.hpp"

namespace lamina::drivers::detail {
namespace {

ControllerStatus report(ControllerState state, int rx_free) {
  ControllerStatus s;
  s.state = state;
  s.state_text = to_string(state);
  s.planner_blocks_free = 100;
  s.rx_bytes_free = rx_free;
  return s;
}
ControllerStatus idle(int rx_free = 1023) { return report(ControllerState::idle, rx_free); }

// Reports every 0.2 s (5 Hz) from `from_s` until `until_s`: the first error, if any, and when.
struct Verdict {
  std::optional<LinkError> error;
  double at_s = 0;
};
Verdict watch(StallWatch& w, const ControllerStatus& s, const LinkCounts& counts, double from_s, double until_s) {
  for (double t = from_s; t <= until_s + 1e-9; t += 0.2)
    if (auto e = w.on_status(s, t, counts)) return {e, t};
  return {};
}

const std::vector<std::string> kPierce{"G0X20Y20", "Z0", "M3", "G4P3", "G1X21F600", "M5"};

TEST(StallWatch, AControllerDwellingIdleIsGivenTheDwellPlusTheMargin) {
  StallWatch w(2.0);
  w.load(kPierce, 0);
  // G0, Z0, M3 answered; the dwell (line 4) waits for its ok, the controller Idle meanwhile.
  const LinkCounts counts{6, 3, LineProtocol::Unanswered{25, 5}};
  const Verdict v = watch(w, idle(1023 - 20), counts, 0, 10);
  ASSERT_TRUE(v.error);
  EXPECT_GT(v.at_s, 3 + 2.0) << "not before the dwell and the margin";
  EXPECT_LT(v.at_s, 3 + 2.0 + 0.5);
}

TEST(StallWatch, AnOrdinaryLineGetsTheMarginOnly) {
  StallWatch w(2.0);
  w.load(kPierce, 0);
  const LinkCounts counts{6, 4, LineProtocol::Unanswered{13, 10}};  // waiting on G1X21F600
  const Verdict v = watch(w, idle(1023 - 13), counts, 0, 10);
  ASSERT_TRUE(v.error);
  EXPECT_GT(v.at_s, 2.0);
  EXPECT_LT(v.at_s, 2.5);
}

TEST(StallWatch, ThreeReportsAtLeastHoweverLongTheyTake) {
  StallWatch w(0.5);
  w.load(kPierce, 0);
  const LinkCounts counts{6, 4, LineProtocol::Unanswered{13, 10}};
  EXPECT_FALSE(w.on_status(idle(1010), 0, counts));
  EXPECT_FALSE(w.on_status(idle(1010), 30, counts)) << "two reports: one may have overtaken the ok";
  EXPECT_TRUE(w.on_status(idle(1010), 31, counts));
}

TEST(StallWatch, AnAnswerOrMotionStartsTheClockAgain) {
  StallWatch w(2.0);
  w.load(kPierce, 0);
  EXPECT_FALSE(watch(w, idle(1010), {6, 4, LineProtocol::Unanswered{13, 10}}, 0, 1.9).error);
  EXPECT_FALSE(watch(w, idle(1017), {6, 5, LineProtocol::Unanswered{3, 3}}, 2.0, 3.9).error) << "an ok came";
  EXPECT_FALSE(w.on_status(report(ControllerState::run, 1017), 4.0, {6, 5, LineProtocol::Unanswered{3, 3}}));
  EXPECT_FALSE(watch(w, idle(1017), {6, 5, LineProtocol::Unanswered{3, 3}}, 4.2, 6.1).error) << "it moved";
}

TEST(StallWatch, RunHoldOrNothingWaitingIsNeverAStall) {
  StallWatch w(0.5);
  w.load(kPierce, 0);
  EXPECT_FALSE(watch(w, report(ControllerState::hold, 1000), {6, 3, LineProtocol::Unanswered{23, 5}}, 0, 60).error);
  EXPECT_FALSE(watch(w, report(ControllerState::run, 1000), {6, 3, LineProtocol::Unanswered{23, 5}}, 0, 60).error);
  EXPECT_FALSE(watch(w, idle(1023), {6, 6, LineProtocol::Unanswered{0, 0}}, 0, 60).error);
}

// Which fault it is: the controller's unread bytes against ours. The empty level is the most
// free bytes it ever reported (1023 on a 1024-byte grblHAL).
TEST(StallWatch, TellsAStallFromLostBytesFromALostAnswer) {
  const LinkCounts counts{6, 4, LineProtocol::Unanswered{13, 10}};  // G1X21F600\n + M5\n
  const auto verdict = [&](int rx_free) {
    StallWatch w(0.5);
    w.load(kPierce, 0);
    EXPECT_FALSE(w.on_status(idle(1023), 0, {0, 0, {}})) << "learns the empty level";
    return watch(w, idle(rx_free), counts, 0.2, 5).error.value();
  };
  const LinkError stalled = verdict(1023 - 13);
  EXPECT_EQ(stalled.code, LinkErrorCode::timeout);
  EXPECT_NE(stalled.message.find("stalled"), std::string::npos) << stalled.message;
  EXPECT_NE(stalled.message.find("all 13 byte(s)"), std::string::npos) << stalled.message;
  EXPECT_NE(stalled.message.find("from line 5"), std::string::npos) << stalled.message;
  const LinkError lost_bytes = verdict(1023 - 12);
  EXPECT_EQ(lost_bytes.code, LinkErrorCode::protocol_error);
  EXPECT_NE(lost_bytes.message.find("bytes lost"), std::string::npos) << lost_bytes.message;
  const LinkError lost_ok = verdict(1023 - 3);
  EXPECT_EQ(lost_ok.code, LinkErrorCode::protocol_error);
  EXPECT_NE(lost_ok.message.find("acknowledgement lost"), std::string::npos) << lost_ok.message;
  EXPECT_NE(lost_ok.message.find("taken 10 byte(s)"), std::string::npos) << lost_ok.message;
}

TEST(StallWatch, WithoutByteCountsItSaysBothAreThePossibleCauses) {
  StallWatch w(0.5);
  w.load(kPierce, 0);
  ControllerStatus s = idle();
  s.rx_bytes_free.reset();  // a Grbl whose $10 leaves Bf out
  const auto e = watch(w, s, {6, 4, std::nullopt}, 0, 5).error;
  ASSERT_TRUE(e);
  EXPECT_EQ(e->code, LinkErrorCode::timeout);
  EXPECT_NE(e->message.find("an answer was lost or it stopped reading"), std::string::npos) << e->message;
}

TEST(StallWatch, SilenceMayLastTheDwellLonger) {
  StallWatch w(2.0);
  w.load(kPierce, 100);
  EXPECT_DOUBLE_EQ(w.silence_allowed_s(10, 3), 13) << "waiting on G4P3";
  EXPECT_DOUBLE_EQ(w.silence_allowed_s(10, 4), 10);
  EXPECT_DOUBLE_EQ(w.silence_allowed_s(10, 99), 10) << "past the span";
}

}  // namespace
}  // namespace lamina::drivers::detail
