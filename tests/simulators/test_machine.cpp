// The simulated CNC's executor: time model, queue, feed hold, reset, alarms, starvation.
#include <gtest/gtest.h>

#include <algorithm>

#include <cmath>
#include <numbers>
#include <vector>

#include "machine.hpp"

namespace lamina::sim {
namespace {

std::vector<ExecutedBlock> blocks(const std::vector<MachineEvent>& events) {
  std::vector<ExecutedBlock> out;
  for (const auto& e : events)
    if (const auto* b = std::get_if<ExecutedBlock>(&e)) out.push_back(*b);
  return out;
}
std::vector<AlarmEvent> alarms(const std::vector<MachineEvent>& events) {
  std::vector<AlarmEvent> out;
  for (const auto& e : events)
    if (const auto* a = std::get_if<AlarmEvent>(&e)) out.push_back(*a);
  return out;
}

// Submit one line and insist it is accepted.
void ok(Machine& m, std::string_view line, double t_s) { ASSERT_EQ(m.submit_line(line, t_s), GrblStatus::ok) << line; }

TEST(Machine, FeedMoveTakesDistanceOverFeed) {
  Machine m({});
  ok(m, "G1X30Y40F600", 0);
  EXPECT_EQ(m.state(), MachineState::run);
  // |(30, 40)| = 50 mm at 600 mm/min = 10 mm/s → 5 s; halfway at 2.5 s is (15, 20).
  EXPECT_NEAR(m.position(2.5)[0], 15, 1e-9);
  EXPECT_NEAR(m.position(2.5)[1], 20, 1e-9);
  EXPECT_NEAR(m.feed_mm_per_min(2.5), 600, 1e-9);
  m.advance(10);
  const auto b = blocks(m.take_events());
  ASSERT_EQ(b.size(), 1u);
  EXPECT_EQ(b[0].seq, 1u);
  EXPECT_EQ(b[0].line, "G1X30Y40F600");
  EXPECT_NEAR(b[0].t_start_s, 0, 1e-12);
  EXPECT_NEAR(b[0].t_end_s, 5, 1e-9);
  EXPECT_NEAR(b[0].end[0], 30, 1e-12);
  EXPECT_TRUE(b[0].completed);
  EXPECT_EQ(m.state(), MachineState::idle);
}

TEST(Machine, RotaryOnlyMoveIsTimedInDegrees) {
  Machine m({});
  ok(m, "G1A90F180", 0);  // 90° at 180 °/min = 0.5 min = 30 s
  m.advance(100);
  const auto b = blocks(m.take_events());
  ASSERT_EQ(b.size(), 1u);
  EXPECT_NEAR(b[0].t_end_s, 30, 1e-9);
  EXPECT_NEAR(b[0].end[3], 90, 1e-12);
}

TEST(Machine, InverseTimeMoveTakesOneOverF) {
  Machine m({});
  ok(m, "G93G1X10A30F12", 0);  // F12 in G93: 1/12 min = 5 s, whatever the distance
  ok(m, "G1X20F6", 0);          // 1/6 min = 10 s
  m.advance(100);
  const auto b = blocks(m.take_events());
  ASSERT_EQ(b.size(), 2u);
  EXPECT_NEAR(b[0].t_end_s, 5, 1e-9);
  EXPECT_NEAR(b[1].t_start_s, 5, 1e-9);
  EXPECT_NEAR(b[1].t_end_s, 15, 1e-9);
}

TEST(Machine, FeedMustBeDefined) {
  Machine m({});
  EXPECT_EQ(m.submit_line("G1X10", 0), GrblStatus::undefined_feed_rate);  // no F yet in G94
  EXPECT_EQ(m.submit_line("G93G1X10", 0), GrblStatus::undefined_feed_rate);  // G93 needs F per line
  EXPECT_EQ(m.accepted_blocks(), 0u);  // refused lines are not queued
  ok(m, "G93G1X10F60", 0);
  EXPECT_EQ(m.submit_line("G1X20", 0), GrblStatus::undefined_feed_rate);  // F is not modal in G93
  ok(m, "G94", 0);
  // The G94 feed is undefined after G93 → G94 (Grbl, RS274NGC).
  EXPECT_EQ(m.submit_line("G1X20", 0), GrblStatus::undefined_feed_rate);
  ok(m, "G1X20F600", 0);
  ok(m, "G1X30", 0);  // now modal
  EXPECT_EQ(m.accepted_blocks(), 4u);
}

TEST(Machine, RapidTakesTheSlowestAxis) {
  Machine m({});
  // X 100 mm at 20000 mm/min = 0.3 s; Z 50 mm at 5000 mm/min = 0.6 s → 0.6 s.
  ok(m, "G0X100Z-50", 0);
  m.advance(10);
  const auto b = blocks(m.take_events());
  ASSERT_EQ(b.size(), 1u);
  EXPECT_NEAR(b[0].t_end_s, 0.6, 1e-9);
}

TEST(Machine, FeedAboveMaximumIsClamped) {
  MachineConfig config;
  config.max_feed_mm_per_min = 600;
  Machine m(config);
  ok(m, "G1X100F6000", 0);  // clamped to 600 mm/min = 10 mm/s → 100 mm in 10 s (not 1 s)
  m.advance(100);
  EXPECT_NEAR(blocks(m.take_events()).at(0).t_end_s, 10, 1e-9);
}

TEST(Machine, InchesAreConvertedToMillimetres) {
  Machine m({});
  ok(m, "G20G1X1F10", 0);  // 1 in = 25.4 mm at 10 in/min = 254 mm/min → 6 s
  ok(m, "G91G1Y2", 0);     // relative 2 in = 50.8 mm, same feed → 12 s
  m.advance(100);
  const auto b = blocks(m.take_events());
  ASSERT_EQ(b.size(), 2u);
  EXPECT_NEAR(b[0].end[0], 25.4, 1e-12);
  EXPECT_NEAR(b[0].t_end_s, 6, 1e-9);
  EXPECT_NEAR(b[1].end[1], 50.8, 1e-12);
  EXPECT_NEAR(b[1].t_end_s, 18, 1e-9);
}

TEST(Machine, ArcTimedByItsLength) {
  Machine m({});
  // CW half circle from (0,0) to (20,0) around (10,0): length π·10 mm at 10 mm/s → π s;
  // going clockwise from the left end it passes the top, (10, 10), halfway.
  ok(m, "G2X20Y0I10J0F600", 0);
  const double half_s = std::numbers::pi / 2;
  EXPECT_NEAR(m.position(half_s)[0], 10, 1e-9);
  EXPECT_NEAR(m.position(half_s)[1], 10, 1e-9);
  m.advance(10);
  EXPECT_NEAR(blocks(m.take_events()).at(0).t_end_s, std::numbers::pi, 1e-9);
  EXPECT_EQ(m.submit_line("G2X0Y0R-5", 10), GrblStatus::arc_radius_error);  // chord 20 > 2·5
  EXPECT_EQ(m.submit_line("G2X0Y0I3", 10), GrblStatus::invalid_target);     // end not on the circle
}

TEST(Machine, QueueCapacityCountsOnlyTimedBlocks) {
  MachineConfig config;
  config.planner_blocks = 2;
  Machine m(config);
  ok(m, "G1X10F60", 0);  // 10 mm at 1 mm/s: runs 0-10 s and holds its slot meanwhile
  ok(m, "(a comment takes no block)", 0);
  ok(m, "G94", 0);
  EXPECT_EQ(m.free_blocks(), 1u);
  EXPECT_EQ(m.queued_blocks(), 3u);
  EXPECT_EQ(m.queued_timed_blocks(), 1u);
  ok(m, "G1X20", 0);
  EXPECT_FALSE(m.has_room());
  EXPECT_EQ(m.free_blocks(), 0u);
  // Full: a move is refused and changes nothing; zero-time lines still go in behind it.
  EXPECT_FALSE(m.has_room_for("G1X30"));
  EXPECT_FALSE(m.has_room_for("X30"));  // modal G1: a move too
  EXPECT_EQ(m.submit_line("G1X30", 0), GrblStatus::overflow);
  EXPECT_EQ(m.accepted_blocks(), 4u);
  EXPECT_FALSE(m.has_room_for("M3"));      // a jet change waits for the queue to drain (planner sync)
  EXPECT_TRUE(m.has_room_for("G1X20"));    // already there: an empty move, no block (grblHAL)
  EXPECT_FALSE(m.has_room_for("G4P0"));    // a dwell syncs too, even with no time
  EXPECT_FALSE(m.has_room_for("G4P0.5"));  // a dwell takes one (our simplification)
  EXPECT_TRUE(m.has_room_for("G1X1B5"));   // an error is answered at once, no block needed
  ok(m, "M3", 0);
  ok(m, "(another comment)", 0);
  EXPECT_EQ(m.free_blocks(), 0u);
  m.advance(10.5);  // block 1 done at 10, the comment and G94 at 10 (zero time), X20 runs 10-20
  EXPECT_EQ(m.queued_timed_blocks(), 1u);
  EXPECT_EQ(m.free_blocks(), 1u);
  EXPECT_EQ(m.queued_blocks(), 3u);  // X20 running, M3 and the comment behind it
  EXPECT_EQ(m.submit_line("%", 10.5), GrblStatus::ok);  // `%` is not queued
  EXPECT_EQ(m.accepted_blocks(), 6u);
  EXPECT_EQ(m.planner_blocks(), 2u);
}

TEST(Machine, FeedHoldDeceleratesHoldsAndResumes) {
  MachineConfig config;
  config.hold_decel_mm_per_s2 = 10;
  Machine m(config);
  ok(m, "G1X100F600", 0);  // 10 mm/s, 10 s
  m.feed_hold(2);          // at X20; stop distance v²/2a = 100/20 = 5 mm in v/a = 1 s
  EXPECT_EQ(m.state(), MachineState::hold_pending);
  // 0.5 s into the ramp: 10·0.5 − 10·0.5²/2 = 3.75 mm past X20.
  EXPECT_NEAR(m.position(2.5)[0], 23.75, 1e-9);
  m.advance(3.5);
  EXPECT_EQ(m.state(), MachineState::hold);
  EXPECT_NEAR(m.position(3.5)[0], 25, 1e-9);
  EXPECT_NEAR(m.position(50)[0], 25, 1e-9);
  m.cycle_start(50);
  EXPECT_EQ(m.state(), MachineState::run);
  EXPECT_NEAR(m.position(50)[0], 25, 1e-9);  // no jump on resume
  EXPECT_NEAR(m.position(51)[0], 35, 1e-9);
  m.advance(100);
  const auto b = blocks(m.take_events());
  ASSERT_EQ(b.size(), 1u);
  EXPECT_NEAR(b[0].t_start_s, 0, 1e-12);
  EXPECT_NEAR(b[0].t_end_s, 57.5, 1e-9);  // 75 mm left at 10 mm/s from t = 50
  EXPECT_TRUE(b[0].completed);
  EXPECT_NEAR(b[0].end[0], 100, 1e-12);
}

TEST(Machine, HoldNearTheEndOfABlockStopsAtItsEnd) {
  MachineConfig config;
  config.hold_decel_mm_per_s2 = 10;
  Machine m(config);
  ok(m, "G1X10F600", 0);
  ok(m, "G1X20", 0);
  m.feed_hold(0.8);  // at X8 with 2 mm left < the 5 mm stop distance: the block ends slowing
  // 10τ − 5τ² = 2 → τ = (10 − √60)/10.
  const double tau_s = (10 - std::sqrt(60.0)) / 10;
  m.advance(5);
  EXPECT_EQ(m.state(), MachineState::hold);
  auto b = blocks(m.take_events());
  ASSERT_EQ(b.size(), 1u);
  EXPECT_NEAR(b[0].t_end_s, 0.8 + tau_s, 1e-9);
  EXPECT_NEAR(m.position(5)[0], 10, 1e-12);  // the next block waits for cycle start
  m.cycle_start(6);
  m.advance(20);
  b = blocks(m.take_events());
  ASSERT_EQ(b.size(), 1u);
  EXPECT_NEAR(b[0].t_start_s, 6, 1e-12);
  EXPECT_NEAR(b[0].t_end_s, 7, 1e-9);
}

TEST(Machine, ResetStopsFlushesAndResetsModalState) {
  Machine m({});
  ok(m, "G91", 0);
  ok(m, "G1X100F600", 0);
  ok(m, "G1X100", 0);
  EXPECT_TRUE(m.reset(3));  // moving: at X30 (10 mm/s for 3 s)
  EXPECT_EQ(m.state(), MachineState::idle);
  const auto b = blocks(m.take_events());
  ASSERT_EQ(b.size(), 2u);  // the G91 line and the cut block; the flushed one has no record
  EXPECT_EQ(b[1].seq, 2u);
  EXPECT_FALSE(b[1].completed);
  EXPECT_NEAR(b[1].end[0], 30, 1e-9);
  EXPECT_NEAR(b[1].t_end_s, 3, 1e-12);
  EXPECT_EQ(m.queued_blocks(), 0u);
  // Defaults again: F undefined, G90 (X50 is absolute: 20 mm from X30 at F1200 → 1 s).
  EXPECT_EQ(m.submit_line("G1X50", 4), GrblStatus::undefined_feed_rate);
  ok(m, "G1X50F1200", 4);
  m.advance(10);
  const auto after = blocks(m.take_events());
  ASSERT_EQ(after.size(), 1u);
  EXPECT_NEAR(after[0].end[0], 50, 1e-12);
  EXPECT_NEAR(after[0].t_end_s, 5, 1e-9);
  EXPECT_FALSE(m.reset(20));  // idle: not moving
}

TEST(Machine, SoftLimitAlarmThenErrorLockUntilUnlock) {
  Machine m({});
  ok(m, "G1X10F600", 0);
  EXPECT_EQ(m.submit_line("G0X-201", 0.5), GrblStatus::soft_limit);  // soft_min X is -200
  EXPECT_EQ(m.state(), MachineState::alarm);
  EXPECT_EQ(m.alarm(), std::optional<GrblAlarm>(GrblAlarm::soft_limit));
  const auto events = m.take_events();
  const auto a = alarms(events);
  ASSERT_EQ(a.size(), 1u);
  EXPECT_EQ(static_cast<int>(a[0].code), 2);
  EXPECT_EQ(a[0].seq, 2u);  // the refused line would have been block 2
  ASSERT_EQ(blocks(events).size(), 1u);
  EXPECT_FALSE(blocks(events)[0].completed);  // the running move was stopped at X5
  EXPECT_EQ(static_cast<int>(m.submit_line("G0X1", 1)), 9);
  EXPECT_EQ(m.submit_line("(even a comment)", 1), GrblStatus::system_gc_lock);
  EXPECT_TRUE(m.unlock());
  EXPECT_EQ(m.state(), MachineState::idle);
  ok(m, "G0X1", 2);

  MachineConfig off;
  off.soft_limits = false;
  Machine free_machine(off);
  ok(free_machine, "G0X-201", 0);
}

TEST(Machine, EstopHoldsTheAlarm) {
  Machine m({});
  m.set_estop(true, 1);
  EXPECT_EQ(m.alarm(), std::optional<GrblAlarm>(GrblAlarm::estop));
  EXPECT_FALSE(m.unlock());
  m.set_estop(false, 2);
  EXPECT_EQ(m.state(), MachineState::alarm);  // released, but still latched until $X
  EXPECT_TRUE(m.unlock());
  EXPECT_EQ(m.state(), MachineState::idle);
}

TEST(Machine, AlarmAtSeqFiresWhenTheBlockStarts) {
  MachineConfig config;
  config.alarm_at_seq = 2;
  Machine m(config);
  ok(m, "G1X10F600", 0);  // 0-1 s
  ok(m, "G1X20", 0);      // would start at 1 s
  ok(m, "G1X30", 0);
  m.advance(0.5);
  EXPECT_EQ(m.state(), MachineState::run);  // queued, not started: no alarm yet
  m.advance(5);
  EXPECT_EQ(m.state(), MachineState::alarm);
  const auto events = m.take_events();
  const auto b = blocks(events);
  ASSERT_EQ(b.size(), 2u);  // block 3 was flushed
  EXPECT_TRUE(b[0].completed);
  EXPECT_EQ(b[1].seq, 2u);
  EXPECT_FALSE(b[1].completed);
  EXPECT_NEAR(b[1].t_start_s, 1, 1e-9);
  EXPECT_NEAR(b[1].t_end_s, 1, 1e-9);
  EXPECT_NEAR(b[1].end[0], 10, 1e-12);  // zero length
  const auto a = alarms(events);
  ASSERT_EQ(a.size(), 1u);
  EXPECT_EQ(a[0].code, GrblAlarm::hard_limit);
  EXPECT_EQ(a[0].seq, 2u);
  EXPECT_NEAR(a[0].t_s, 1, 1e-9);
}

TEST(Machine, StarvationWhenTheSenderIsSlow) {
  Machine m({});
  ok(m, "G1X10F600", 0);  // runs 0-1 s
  ok(m, "G1X20", 2);      // arrives late: the queue was empty from 1 s to 2 s
  ok(m, "G1X30", 2.5);    // queued behind: no gap
  ok(m, "M2", 4.5);       // block 3 ends at 4 s; the M2 comes half a second later
  m.advance(20);
  const auto events = m.take_events();
  std::vector<StarvationEvent> starving;
  for (const auto& e : events)
    if (const auto* s = std::get_if<StarvationEvent>(&e)) starving.push_back(*s);
  // Once at 1 s (after block 1), once at 4 s (after block 3); none after M2 ends the program.
  ASSERT_EQ(starving.size(), 2u);
  EXPECT_NEAR(starving[0].t_s, 1, 1e-9);
  EXPECT_EQ(starving[0].after_seq, 1u);
  EXPECT_NEAR(starving[1].t_s, 4, 1e-9);
  EXPECT_EQ(starving[1].after_seq, 3u);
  EXPECT_EQ(m.starvation_count(), 2u);
  EXPECT_EQ(blocks(events).size(), 4u);
}

TEST(Machine, NoStarvationWhenTheQueueIsKeptFull) {
  Machine m({});
  for (int i = 1; i <= 20; ++i) ok(m, "G1X" + std::to_string(i) + "F600", 0.05 * i);  // 0.1 s each
  ok(m, "M2", 1);  // all queued before block 10 even starts: never empty
  m.advance(100);
  EXPECT_EQ(m.starvation_count(), 0u);
  EXPECT_EQ(m.executed_blocks(), 21u);
}

TEST(Machine, SetUpLinesArrivingSlowlyAreNoStarvation) {
  Machine m({});
  ok(m, "G21G90G94", 0);  // no time: the machine never moved, so waiting for line 2 is no stop
  ok(m, "M3", 0.5);
  ok(m, "G1X10F600", 1);  // 1-2 s, then the queue runs dry: that one is starvation
  m.advance(3);
  ASSERT_EQ(m.starvation_count(), 1u);
  const auto events = m.take_events();
  const auto it = std::find_if(events.begin(), events.end(),
                               [](const MachineEvent& e) { return std::holds_alternative<StarvationEvent>(e); });
  ASSERT_NE(it, events.end());
  EXPECT_NEAR(std::get<StarvationEvent>(*it).t_s, 2, 1e-9);
}

TEST(Machine, JetChangesProgramEndAndDwellWaitForTheQueueToDrain) {
  Machine m({});
  ok(m, "G1X10F600", 0);  // 0-1 s
  EXPECT_FALSE(m.has_room_for("M3")) << "the jet waits for the motion before it";
  EXPECT_FALSE(m.has_room_for("M5"));
  EXPECT_FALSE(m.has_room_for("M30"));
  EXPECT_FALSE(m.has_room_for("G4P0.5"));
  EXPECT_TRUE(m.has_room_for("G1X20")) << "motion is planned ahead";
  EXPECT_TRUE(m.has_room_for("(CONTOUR 2)"));
  EXPECT_TRUE(m.has_room_for("G94"));
  m.advance(1.0);
  EXPECT_TRUE(m.has_room_for("M3"));
  ok(m, "M3", 1.0);
  ok(m, "G1X20", 1.0);  // 1-2 s
  ok(m, "M30", 1.0);    // queued behind it (submit_line itself does not sync): the program ends at 2 s
  m.advance(5);
  EXPECT_EQ(m.starvation_count(), 0u) << "the drain before M3 was asked for: no starvation";
  // A slow sender is still starvation: the queue ran dry with no sync waiting.
  ok(m, "G1X30", 5);  // 5-6 s
  ok(m, "G1X40", 7);  // 7-8 s: the queue was dry from 6 s
  ok(m, "M30", 7);
  m.advance(10);
  EXPECT_EQ(m.starvation_count(), 1u);
}

TEST(Machine, ProgramEndStopsTheJetAndEndsTheProgram) {
  Machine m({});
  ok(m, "G1X10F600", 0);  // 0-1 s
  ok(m, "M3", 0);
  EXPECT_FALSE(m.jet_commanded());  // queued, not executed
  m.advance(1.5);
  EXPECT_TRUE(m.jet_commanded());
  ok(m, "G91G1X10", 1.5);
  ok(m, "M2", 1.5);
  m.advance(5);
  EXPECT_FALSE(m.jet_commanded());
  EXPECT_EQ(m.state(), MachineState::idle);
  const auto b = blocks(m.take_events());
  ASSERT_EQ(b.size(), 4u);
  EXPECT_TRUE(b[1].jet);   // the M3 block runs with the jet on
  EXPECT_TRUE(b[2].jet);
  EXPECT_FALSE(b[3].jet);  // M2 turned it off
  m.advance(50);
  EXPECT_EQ(m.starvation_count(), 1u);  // only the gap after block 1, before the late G91 line
  // M2 restored G90: X5 is absolute now (from X20).
  ok(m, "G1X5", 60);
  m.advance(100);
  EXPECT_NEAR(m.position(100)[0], 5, 1e-12);
}

TEST(Machine, ProgramIsLoggedLineForLine) {
  Machine m({});
  const std::vector<std::string> program{"%", "(title)", "G21G90G94G17", "", "N10 G0 Z5", "M3", "G4P0.5",
                                         "G1X10F600", "M5", "M2", "%"};
  for (const auto& line : program) ok(m, line, 0);
  m.advance(100);
  const auto b = blocks(m.take_events());
  ASSERT_EQ(b.size(), program.size() - 2);  // every line but the two `%`
  for (std::size_t i = 0; i < b.size(); ++i) {
    EXPECT_EQ(b[i].seq, i + 1);
    EXPECT_EQ(b[i].line, program[i + 1]);
  }
  // G0 Z5: 5 mm at 5000 mm/min = 0.06 s; dwell 0.5 s; then 10 mm at 10 mm/s = 1 s.
  EXPECT_NEAR(b[5].t_start_s, 0.06, 1e-9);
  EXPECT_NEAR(b[5].t_end_s, 0.56, 1e-9);
  EXPECT_NEAR(b[6].t_end_s, 1.56, 1e-9);
}

}  // namespace
}  // namespace lamina::sim

namespace lamina::sim {
namespace {

TEST(Machine, HoldWhileIdleKeepsLinesQueuedAndDwellClockStops) {
  Machine m({});
  m.feed_hold(0);
  EXPECT_EQ(m.state(), MachineState::hold);
  ok(m, "G4P2", 1);
  m.advance(5);
  EXPECT_EQ(m.executed_blocks(), 0u);  // nothing starts while held
  m.cycle_start(5);                    // dwell runs 5-7 s
  m.feed_hold(6);                      // 1 s done: a dwell has nothing to decelerate
  EXPECT_EQ(m.state(), MachineState::hold);
  m.cycle_start(10);                   // 1 s left → ends at 11 s
  EXPECT_FALSE(m.reset(10.5));         // dwelling: no axis moving
  // The reset cut the dwell short at 10.5 s.
  const auto b = blocks(m.take_events());
  ASSERT_EQ(b.size(), 1u);
  EXPECT_FALSE(b[0].completed);
  EXPECT_NEAR(b[0].t_start_s, 5, 1e-12);
  EXPECT_NEAR(b[0].t_end_s, 10.5, 1e-12);
}

TEST(Machine, DwellResumedAfterHoldEndsOnTime) {
  Machine m({});
  ok(m, "G4P2", 0);  // 0-2 s
  m.feed_hold(0.5);
  m.cycle_start(3);  // 1.5 s left → 4.5 s
  m.advance(10);
  EXPECT_NEAR(blocks(m.take_events()).at(0).t_end_s, 4.5, 1e-9);
}

TEST(Machine, OnlyMovesAreCheckedAgainstSoftLimits) {
  MachineConfig config;
  config.soft_min[0] = 10;  // the machine powers up at X0, outside
  Machine m(config);
  ok(m, "(title)", 0);
  ok(m, "G21G90", 0);
  ok(m, "G0X20", 0);  // moving back inside is allowed: the target is checked
  EXPECT_EQ(m.submit_line("G0X5", 1), GrblStatus::soft_limit);
}

TEST(Machine, ArcBulgingPastALimitIsRefused) {
  MachineConfig y_from_zero;
  y_from_zero.soft_min[1] = 0;
  Machine m(y_from_zero);
  ok(m, "G0X10Y5", 0);
  // CCW half circle (10,5) → (30,5) around (20,5) goes below through (20,-5): Y < 0.
  EXPECT_EQ(m.submit_line("G3X30Y5I10J0F600", 1), GrblStatus::soft_limit);
  MachineConfig config;
  Machine cw(config);
  ok(cw, "G0X10Y5", 0);
  ok(cw, "G2X30Y5I10J0F600", 1);  // the CW one passes above through (20,15): inside
}

}  // namespace
}  // namespace lamina::sim

namespace lamina::sim {
namespace {

TEST(Machine, SameStartAndEndWithIJIsAFullCircle) {
  Machine m({});
  ok(m, "G0X10Y10", 0);  // 10 mm at 20000 mm/min: 0.03 s
  m.advance(1);
  // Centre (20,10), r = 10: 2π·10 mm at 10 mm/s → 2π s; a quarter of the way clockwise from
  // the left end (angle π → π/2) is the top, (20, 20).
  ok(m, "G2X10Y10I10F600", 1);
  EXPECT_NEAR(m.position(1 + std::numbers::pi / 2)[0], 20, 1e-9);
  EXPECT_NEAR(m.position(1 + std::numbers::pi / 2)[1], 20, 1e-9);
  m.advance(20);
  const auto b = blocks(m.take_events());
  ASSERT_EQ(b.size(), 2u);
  EXPECT_NEAR(b[1].t_end_s - b[1].t_start_s, 2 * std::numbers::pi, 1e-9);
}

}  // namespace
}  // namespace lamina::sim
