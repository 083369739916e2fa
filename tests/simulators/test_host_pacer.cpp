// --pace-to-host: the simulated clock drops to real time while the host falls behind, exactly at
// the instant the controller's lead reaches the low mark, and goes back to the time scale once the
// host has caught up. A host that pauses briefly then no longer starves a compressed machine; one
// that pauses longer than a real machine's lead still does.
#include <gtest/gtest.h>

#include "host_pacer.hpp"
#include "machine.hpp"

namespace lamina::sim {
namespace {

// A 100-block planner holding `blocks` blocks of `block_s` each.
ControllerLead lead_of(std::size_t blocks, double block_s, std::size_t capacity = 100) {
  const double half_s = blocks > capacity / 2 ? static_cast<double>(blocks - capacity / 2) * block_s : 0.0;
  return {static_cast<double>(blocks) * block_s, half_s, blocks, capacity};
}

TEST(HostPacer, RunsFastTowardsTheLowMarkAndNamesTheInstantItIsReached) {
  HostPacer p({.low_lead_s = 1.0, .high_lead_s = 2.0});
  const PaceDecision d = p.decide(10.0, lead_of(60, 0.02), true, 50);  // 1.2 s, the half mark in 0.2 s
  EXPECT_EQ(d.scale, 50);
  ASSERT_TRUE(d.slow_from_s);
  EXPECT_DOUBLE_EQ(*d.slow_from_s, 10.2) << "the lead falls 1:1 with simulated time";
  EXPECT_EQ(d.slow_scale, 1);
  EXPECT_FALSE(p.slowed());
  // Long blocks: half the planner is reached before the lead falls under 1 s: the later instant.
  EXPECT_DOUBLE_EQ(*p.decide(10.0, lead_of(60, 0.5), true, 50).slow_from_s, 10.0 + 30 - 1);
}

TEST(HostPacer, BelowTheLowMarkRunsAtRealTimeUntilTheHostCatchesUp) {
  HostPacer p({.low_lead_s = 1.0, .high_lead_s = 2.0});
  EXPECT_EQ(p.decide(0, lead_of(40, 0.02), true, 40).scale, 1);
  EXPECT_TRUE(p.slowed());
  EXPECT_EQ(p.decide(1, lead_of(70, 0.02), true, 40).scale, 1) << "between the marks: stays slow (hysteresis)";
  EXPECT_EQ(p.decide(2, lead_of(75, 0.02), true, 40).scale, 40) << "the planner ¾ full again";
  EXPECT_EQ(p.decide(3, lead_of(10, 0.02), true, 40).scale, 1);
  EXPECT_EQ(p.decide(4, lead_of(10, 0.25), true, 40).scale, 40) << "2.5 s of motion: the high mark";
  EXPECT_EQ(p.slowdowns(), 2u);
}

TEST(HostPacer, AFullSmallPlannerIsNotAHostFallingBehind) {
  HostPacer p;
  const PaceDecision d = p.decide(5, lead_of(16, 0.03, 16), true, 10);  // 0.48 s of motion, but full
  EXPECT_EQ(d.scale, 10);
  ASSERT_TRUE(d.slow_from_s);
  EXPECT_NEAR(*d.slow_from_s, 5 + 8 * 0.03, 1e-12) << "real time once half of it ran down";
  EXPECT_FALSE(p.slowed());
}

TEST(HostPacer, AStopTheProgramAsksForIsNotTheHostsToFill) {
  HostPacer p;
  const PaceDecision d = p.decide(0, lead_of(3, 0.03), false, 20);
  EXPECT_EQ(d.scale, 20) << "a sync, a dwell or the program's end drains the queue on purpose";
  EXPECT_FALSE(d.slow_from_s);
  EXPECT_EQ(p.slowdowns(), 0u);
}

TEST(HostPacer, NeverFasterThanAskedWhenTheScaleIsBelowRealTime) {
  HostPacer p;
  EXPECT_EQ(p.decide(0, lead_of(3, 0.03), true, 0.5).scale, 0.5);
}

TEST(MachineLead, CountsTheRunningBlocksRestAndTheQueueAndKnowsWhoOwesTheNextLine) {
  MachineConfig cfg;
  cfg.soft_limits = false;
  Machine m(cfg);
  EXPECT_EQ(m.motion_ahead_s(0), 0);
  EXPECT_FALSE(m.runs_on_host_lines()) << "idle: nothing runs";
  ASSERT_EQ(m.submit_line("G1X10F600", 0), GrblStatus::ok);  // 1 s
  ASSERT_EQ(m.submit_line("G1X30F600", 0), GrblStatus::ok);  // 2 s
  EXPECT_NEAR(m.motion_ahead_s(0.25), 2.75, 1e-9);
  EXPECT_NEAR(m.time_until_blocks_left(0.25, 1), 0.75, 1e-9);
  EXPECT_EQ(m.time_until_blocks_left(0.25, 2), 0);
  EXPECT_TRUE(m.runs_on_host_lines());
  m.feed_hold(0.5);
  m.advance(2.0);
  EXPECT_FALSE(m.runs_on_host_lines()) << "held: the host owes nothing";
  m.cycle_start(2.0);
  m.advance(2.1);
  EXPECT_TRUE(m.runs_on_host_lines());
  EXPECT_FALSE(m.has_room_for("M5")) << "the jet change waits for the drain";
  EXPECT_FALSE(m.runs_on_host_lines()) << "a sync drains the queue on purpose";
}

}  // namespace
}  // namespace lamina::sim
