// The feed-hold rule for the jet (issue 16, item 1), sans-IO: states and times in, actions out.
#include <gtest/gtest.h>

#include "hold_guard.hpp"

namespace lamina::drivers::detail {
namespace {

using S = ControllerState;

HoldGuard guard(double limit_s = 60, double restart_s = 1.0) {
  return HoldGuard({.hold_limit_s = limit_s, .jet_restart_s = restart_s});
}

TEST(HoldGuard, TheJetGoesOffOnlyOnceTheHoldIsComplete) {
  auto g = guard();
  EXPECT_EQ(g.on_state(S::run, 0.0), HoldAction::none);
  EXPECT_EQ(g.on_state(S::hold_pending, 0.1), HoldAction::none) << "decelerating along the path: still cutting";
  EXPECT_EQ(g.on_state(S::hold_pending, 0.2), HoldAction::none);
  EXPECT_EQ(g.on_state(S::hold, 0.3), HoldAction::jet_off);
  EXPECT_EQ(g.on_state(S::hold, 0.4), HoldAction::none) << "once";
  EXPECT_TRUE(g.jet_off_by_hold());
}

TEST(HoldGuard, ResumeOpensTheJetWaitsItsRestartTimeThenContinues) {
  auto g = guard(60, 1.5);
  g.on_state(S::hold, 0.0);
  EXPECT_EQ(g.on_resume_request(10.0), HoldAction::jet_on);
  EXPECT_EQ(g.on_resume_request(10.1), HoldAction::none) << "a second press while resuming does nothing";
  EXPECT_EQ(g.on_state(S::hold, 10.2), HoldAction::none);
  EXPECT_EQ(g.on_state(S::hold, 11.4), HoldAction::none);
  EXPECT_EQ(g.on_state(S::hold, 11.5), HoldAction::cycle_start);
  EXPECT_EQ(g.on_state(S::hold, 11.6), HoldAction::none) << "the cycle start is on its way";
  EXPECT_EQ(g.on_state(S::run, 11.7), HoldAction::none);
  EXPECT_FALSE(g.jet_off_by_hold());
  // The next hold is a new one: jet off again.
  EXPECT_EQ(g.on_state(S::hold, 20.0), HoldAction::jet_off);
}

// The restart time runs from the PLC's confirmation: a jet-on that took 0.4 s to reach the PLC
// still gets its whole 1.5 s before the motion.
TEST(HoldGuard, TheRestartTimeCountsFromTheJetOpeningNotFromTheRequest) {
  auto g = guard(60, 1.5);
  g.on_state(S::hold, 0.0);
  EXPECT_EQ(g.on_resume_request(10.0), HoldAction::jet_on);
  g.on_jet_opened(10.4);
  EXPECT_EQ(g.on_state(S::hold, 11.5), HoldAction::none) << "1.5 s after the request, 1.1 s after the jet opened";
  EXPECT_EQ(g.on_state(S::hold, 11.9), HoldAction::cycle_start);
  g.on_jet_opened(12.5);  // late news changes nothing once the motion was asked for
  EXPECT_EQ(g.on_state(S::hold, 12.6), HoldAction::none);
}

TEST(HoldGuard, AResumeBeforeTheHoldCompletedIsAPlainCycleStart) {
  auto g = guard();
  g.on_state(S::hold_pending, 0.0);
  EXPECT_EQ(g.on_resume_request(0.1), HoldAction::cycle_start);
  EXPECT_FALSE(g.jet_off_by_hold());
}

TEST(HoldGuard, AHoldLongerThanTheLimitBecomesAStop) {
  auto g = guard(30);
  g.on_state(S::hold_pending, 0.0);  // the limit counts from standing still
  EXPECT_EQ(g.on_state(S::hold, 5.0), HoldAction::jet_off);
  EXPECT_EQ(g.on_state(S::hold, 35.0), HoldAction::none);
  EXPECT_EQ(g.on_state(S::hold, 35.1), HoldAction::stop);
  ASSERT_TRUE(g.stop_reason());
  EXPECT_EQ(g.stop_reason()->code, LinkErrorCode::held_too_long);
  EXPECT_NE(g.stop_reason()->message.find("30 s"), std::string::npos) << g.stop_reason()->message;
  EXPECT_EQ(g.on_state(S::hold, 40.0), HoldAction::none) << "stopped once";
  EXPECT_EQ(g.on_resume_request(41.0), HoldAction::none) << "a stopped job resumes from its contour, not here";
}

TEST(HoldGuard, LeavingTheHoldWithoutLaminaWhileTheJetIsOffIsAStop) {
  auto g = guard();
  g.on_state(S::hold, 0.0);
  EXPECT_EQ(g.on_state(S::run, 3.0), HoldAction::stop);
  EXPECT_EQ(g.stop_reason()->code, LinkErrorCode::left_hold_without_jet);
}

TEST(HoldGuard, MovingBeforeTheJetHasStabilisedIsAStop) {
  auto g = guard(60, 2.0);
  g.on_state(S::hold, 0.0);
  g.on_resume_request(1.0);
  EXPECT_EQ(g.on_state(S::run, 1.5), HoldAction::stop);
}

TEST(HoldGuard, IdleAlarmAndDoorAreLeftToTheirOwnPaths) {
  auto g = guard(1);
  for (S s : {S::idle, S::alarm, S::door, S::unknown}) EXPECT_EQ(g.on_state(s, 100.0), HoldAction::none);
  EXPECT_FALSE(g.jet_off_by_hold());
}

}  // namespace
}  // namespace lamina::drivers::detail
