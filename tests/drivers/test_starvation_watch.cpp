// The starvation rule (starvation_watch.hpp) and the hold it leads to (hold_guard.hpp), sans-IO.
#include <gtest/gtest.h>

#include "hold_guard.hpp"
#include "starvation_watch.hpp"

namespace lamina::drivers::detail {
namespace {

using S = ControllerState;

const std::vector<std::string> kProgram{"G21G90", "G0X0Y0", "M3", "G4P0.5", "G1X1F600", "G1X2", "G1X3", "M5", "M30"};

StarvationReading reading(S state, std::size_t at, std::size_t sent_end, double t_s, bool water = true) {
  return {.cnc_state = state, .water_flowing = water, .standing_at = at, .lines_sent_end = sent_end, .read_at_s = t_s};
}

TEST(StarvationWatch, IdleWithTheWaterOnAtALineNotSentIsStarvationAtOnce) {
  StarvationWatch w(kProgram);
  const auto dry = w.on_reading(reading(S::idle, 5, 5, 1.0));
  ASSERT_TRUE(dry);
  EXPECT_TRUE(dry->host_behind) << "a hold: the link is sound";
  EXPECT_EQ(dry->why.code, LinkErrorCode::starved);
  EXPECT_NE(dry->why.message.find("line 6"), std::string::npos) << dry->why.message;
  EXPECT_NE(dry->why.message.find("had not sent"), std::string::npos) << dry->why.message;
}

TEST(StarvationWatch, ALineTheControllerHasNeedsASecondReadingAndIsAStall) {
  StarvationWatch w(kProgram);
  EXPECT_FALSE(w.on_reading(reading(S::idle, 5, 8, 1.0))) << "between a dwell's end and the next block";
  EXPECT_FALSE(w.on_reading(reading(S::idle, 5, 8, 1.0 + StarvationWatch::kConfirmS / 2)));
  const auto dry = w.on_reading(reading(S::idle, 5, 8, 1.0 + StarvationWatch::kConfirmS));
  ASSERT_TRUE(dry);
  EXPECT_FALSE(dry->host_behind) << "a stop: the controller has the line";
  EXPECT_EQ(dry->why.code, LinkErrorCode::timeout);
  EXPECT_NE(dry->why.message.find("stalled"), std::string::npos) << dry->why.message;
  // It moved on between the readings: a new block starts the confirmation again.
  StarvationWatch w2(kProgram);
  EXPECT_FALSE(w2.on_reading(reading(S::idle, 4, 8, 1.0)));
  EXPECT_FALSE(w2.on_reading(reading(S::idle, 5, 8, 1.1)));
}

TEST(StarvationWatch, ADwellASyncLineTheEndDryOrMovingAreNotStarvation) {
  StarvationWatch w(kProgram);
  EXPECT_FALSE(w.on_reading(reading(S::idle, 3, 4, 1.0))) << "G4: grblHAL reports Idle through a dwell";
  EXPECT_FALSE(w.on_reading(reading(S::idle, 7, 7, 1.0))) << "M5 waits for the motion before it";
  EXPECT_FALSE(w.on_reading(reading(S::idle, 9, 9, 1.0))) << "past the program's end";
  EXPECT_FALSE(w.on_reading(reading(S::idle, 5, 5, 1.0, false))) << "no water: standing is harmless";
  EXPECT_FALSE(w.on_reading(reading(S::run, 5, 5, 1.0)));
  EXPECT_FALSE(w.on_reading(reading(S::hold, 5, 5, 1.0))) << "a hold is the hold guard's";
  StarvationReading unknown = reading(S::idle, 5, 5, 1.0);
  unknown.standing_at.reset();
  EXPECT_FALSE(w.on_reading(unknown)) << "no executed count: nothing to judge";
}

HoldGuard guard() { return HoldGuard({.hold_limit_s = 60, .jet_restart_s = 0.5}); }

TEST(HoldGuard, AStarvedMachineIsHeldOnceAndResumedAsAfterAHold) {
  auto g = guard();
  EXPECT_EQ(g.on_starved(1.0), HoldAction::starved_hold);
  EXPECT_EQ(g.on_starved(1.1), HoldAction::none) << "once";
  EXPECT_TRUE(g.jet_off_by_hold());
  EXPECT_EQ(g.on_state(S::idle, 1.1), HoldAction::none) << "standing, the jet already off";
  EXPECT_EQ(g.on_state(S::hold, 1.2), HoldAction::none);
  EXPECT_EQ(g.on_resume_request(5.0), HoldAction::jet_on);
  EXPECT_EQ(g.on_state(S::hold, 5.4), HoldAction::none);
  EXPECT_EQ(g.on_state(S::hold, 5.5), HoldAction::cycle_start);
  EXPECT_EQ(g.on_state(S::run, 5.6), HoldAction::none);
  EXPECT_FALSE(g.jet_off_by_hold());
  EXPECT_EQ(g.on_starved(9.0), HoldAction::starved_hold) << "a new starvation later is a new hold";
}

TEST(HoldGuard, AStarvedControllerThatStaysIdleIsResumedToo) {
  auto g = guard();
  g.on_starved(1.0);
  EXPECT_EQ(g.on_resume_request(2.0), HoldAction::jet_on);
  EXPECT_EQ(g.on_state(S::idle, 2.5), HoldAction::cycle_start) << "a controller that never entered Hold";
}

TEST(HoldGuard, MotionAfterAStarvationBeforeTheResumeIsAStopEvenDecelerating) {
  auto g = guard();
  g.on_starved(1.0);
  EXPECT_EQ(g.on_state(S::hold_pending, 1.05), HoldAction::stop) << "lines reached it before the hold";
  EXPECT_EQ(g.stop_reason()->code, LinkErrorCode::left_hold_without_jet);
  EXPECT_NE(g.stop_reason()->message.find("ran dry"), std::string::npos) << g.stop_reason()->message;
}

TEST(HoldGuard, NoStarvationHoldWhileAHoldHasTheJetOffOrAfterAStop) {
  auto g = guard();
  g.on_state(S::hold, 0.0);  // jet_off
  EXPECT_EQ(g.on_starved(0.5), HoldAction::none);
  g.on_state(S::run, 1.0);   // left it by itself: a stop
  EXPECT_EQ(g.on_starved(2.0), HoldAction::none);
}

}  // namespace
}  // namespace lamina::drivers::detail
