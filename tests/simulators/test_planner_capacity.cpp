// What occupies the planner: only timed blocks (moves, dwells), as in grblHAL, so that a host
// counting "acknowledged lines minus the motion blocks Bf says are queued" knows how far the
// machine got. The machine on its own, then the grbl and xonxoff personalities in front of it.
#include <gtest/gtest.h>

#include <string>
#include <variant>
#include <vector>

#include "grbl_protocol.hpp"
#include "machine.hpp"
#include "protocol_harness.hpp"
#include "xonxoff_protocol.hpp"

namespace lamina::sim {
namespace {

using test::count_of;
using test::ProtocolHarness;

std::vector<ExecutedBlock> executed(const std::vector<MachineEvent>& events) {
  std::vector<ExecutedBlock> out;
  for (const auto& e : events)
    if (const auto* b = std::get_if<ExecutedBlock>(&e)) out.push_back(*b);
  return out;
}

void submit_ok(Machine& m, std::string_view line, double t_s) { ASSERT_EQ(m.submit_line(line, t_s), GrblStatus::ok) << line; }

// The host's side of the contract (written here again: the simulator links nothing from
// drivers/): of `accepted` program lines, the last `queued` moves (the running one included)
// are not finished, and neither is anything after the first of them. Every move in these
// programs starts with G1 and goes somewhere.
std::size_t first_unfinished(const std::vector<std::string>& program, std::size_t accepted, std::size_t queued) {
  std::size_t first = accepted;
  while (queued > 0 && first > 0)
    if (program[--first].starts_with("G1")) --queued;
  return first;
}

TEST(MachinePlannerCapacity, CommentsBetweenMovesTakeNoCapacityAndAreLoggedWhenReached) {
  MachineConfig config;
  config.planner_blocks = 4;
  Machine m(config);
  std::vector<std::string> program{"G21", "G90", "G94"};
  for (int i = 1; i <= 6; ++i) {
    for (int c = 0; c < 3; ++c) program.push_back("(CONTOUR " + std::to_string(i) + " note " + std::to_string(c) + ")");
    program.push_back("G1X" + std::to_string(i * 10) + "F600");  // 10 mm at 10 mm/s: 1 s each
  }
  program.push_back("M30");
  std::size_t next = 0;
  for (; next < program.size() && m.has_room_for(program[next]); ++next) submit_ok(m, program[next], 0);
  // Four moves fill the planner; every line before the fifth move got in.
  EXPECT_EQ(m.free_blocks(), 0u);
  EXPECT_EQ(m.queued_timed_blocks(), 4u);
  EXPECT_EQ(program[next], "G1X50F600");
  EXPECT_EQ(next, 3u + 4 * 4 + 3);
  double t = 0;
  while (next < program.size()) {
    t += 0.25;
    m.advance(t);
    for (; next < program.size() && m.has_room_for(program[next]); ++next) submit_ok(m, program[next], t);
    EXPECT_EQ(first_unfinished(program, next, 4 - m.free_blocks()), m.executed_blocks()) << "t " << t;
  }
  m.advance(100);
  std::vector<std::string> logged;
  for (const auto& b : executed(m.take_events())) {
    logged.push_back(b.line);
    if (b.line.starts_with("(")) {
      EXPECT_EQ(b.t_start_s, b.t_end_s) << b.line;
    }
  }
  EXPECT_EQ(logged, program);
}

TEST(MachinePlannerCapacity, SoftLimitAlarmsEvenWithThePlannerFull) {
  MachineConfig config;
  config.planner_blocks = 1;
  Machine m(config);
  submit_ok(m, "G1X10F600", 0);
  EXPECT_TRUE(m.has_room_for("G0X5000"));  // grblHAL checks the target before waiting for a block
  EXPECT_EQ(m.submit_line("G0X5000", 0), GrblStatus::soft_limit);
  ASSERT_TRUE(m.alarm().has_value());
  EXPECT_EQ(*m.alarm(), GrblAlarm::soft_limit);
}

struct CapacityGrbl : ProtocolHarness {
  explicit CapacityGrbl(std::size_t planner_blocks) : ProtocolHarness(config(planner_blocks)) {
    protocol = make_grbl_protocol(machine, {});
    protocol->on_connect(now_s);
    take();
  }
  static MachineConfig config(std::size_t planner_blocks) {
    MachineConfig c;
    c.planner_blocks = planner_blocks;
    return c;
  }
  // Bf's first field, asked without polling (so no `ok` slips into the answer).
  int bf_blocks() {
    send_burst("?");
    const std::string report = take();
    const auto at = report.find("|Bf:");
    if (at == std::string::npos) {
      ADD_FAILURE() << "no status report in: " << report;
      return -1;
    }
    return std::stoi(report.substr(at + 4));
  }
};

TEST(GrblPlannerCapacity, BfCountsOnlyTheMoves) {
  CapacityGrbl g(4);
  std::string text = "G21\nG94\nM3\nG1 X10 F600\n";
  for (int i = 0; i < 10; ++i) text += "(note)\n";
  g.send(text + "G1 X20\n;\n");
  EXPECT_EQ(count_of(g.take(), "ok"), 16);
  EXPECT_EQ(g.bf_blocks(), 2);  // two moves queued (one running); 14 other lines took none
  EXPECT_EQ(g.machine.queued_timed_blocks(), 2u);
}

TEST(GrblPlannerCapacity, CommentsAreAcknowledgedOnceTheMoveBeforeThemHasABlock) {
  CapacityGrbl g(4);
  // 1 s per move (10 mm at 10 mm/s); ten comments after the 4th move and after the 5th.
  std::vector<std::string> program{"G1 X10 F600", "G1 X20", "G1 X30", "G1 X40"};
  for (int i = 0; i < 10; ++i) program.push_back("(after 4, " + std::to_string(i) + ")");
  program.push_back("G1 X50");
  for (int i = 0; i < 10; ++i) program.push_back("(after 5, " + std::to_string(i) + ")");
  program.push_back("G1 X60");
  std::string text;
  for (const auto& line : program) text += line + "\n";
  g.send(text);
  // Four moves fill the planner; the comments behind the 4th pass, those behind the 5th wait.
  EXPECT_EQ(count_of(g.take(), "ok"), 14);
  EXPECT_EQ(g.bf_blocks(), 0);
  g.run_for(0.95);
  EXPECT_EQ(count_of(g.take(), "ok"), 0);
  g.run_for(0.1);  // the first move ends at 1 s: the 5th gets its block, then its 10 comments
  EXPECT_EQ(count_of(g.take(), "ok"), 11);
  EXPECT_EQ(g.bf_blocks(), 0);
  g.run_for(1.0);
  EXPECT_EQ(count_of(g.take(), "ok"), 1);
  EXPECT_EQ(g.bf_blocks(), 0);
  g.run_for(10.0);
  EXPECT_EQ(g.bf_blocks(), 4);
  EXPECT_EQ(g.executed_lines(), program);
}

TEST(GrblPlannerCapacity, BfTellsTheHostHowFarTheMachineGot) {
  CapacityGrbl g(4);
  std::vector<std::string> program{"G21", "G90", "G94", "M3"};
  for (int i = 1; i <= 12; ++i) {
    program.push_back("(CONTOUR " + std::to_string(i) + ")");
    program.push_back("G1 X" + std::to_string(i * 5) + " F600");  // 0.5 s each
    program.push_back(";");
  }
  program.push_back("M5");
  program.push_back("M30");
  std::string text;
  for (const auto& line : program) text += line + "\n";
  g.send(text);
  std::size_t acked = static_cast<std::size_t>(count_of(g.take(), "ok"));
  EXPECT_EQ(acked, 4u + 4 * 3 + 1);  // up to the 5th move (after its CONTOUR line), which waits
  while (g.now_s < 8) {
    g.run_for(0.05);
    acked += static_cast<std::size_t>(count_of(g.take(), "ok"));
    const int bf = g.bf_blocks();
    ASSERT_GE(bf, 0);
    EXPECT_EQ(first_unfinished(program, acked, 4 - static_cast<std::size_t>(bf)), g.executed_lines().size())
        << "t " << g.now_s;
  }
  EXPECT_EQ(acked, program.size());
  EXPECT_EQ(g.executed_lines(), program);
}

struct XonXoff : ProtocolHarness {
  explicit XonXoff(std::size_t planner_blocks) : ProtocolHarness(CapacityGrbl::config(planner_blocks)) {
    protocol = make_xonxoff_protocol(machine, {});
  }
};

TEST(XonXoffPlannerCapacity, OnlyMotionBlocksWaitForThePlanner) {
  XonXoff x(2);
  std::vector<std::string> program{"G1 X10 F600", "G1 X20"};
  for (int i = 0; i < 5; ++i) program.push_back("(after 2, " + std::to_string(i) + ")");
  program.push_back("G1 X30");
  for (int i = 0; i < 5; ++i) program.push_back("(after 3, " + std::to_string(i) + ")");
  program.push_back("M30");
  std::string text = "%\n";
  for (const auto& line : program) text += line + "\n";
  x.send(text + "%");
  EXPECT_EQ(x.machine.accepted_blocks(), 7u);  // two moves and the comments after them
  EXPECT_EQ(x.protocol->counters().lines_received, 7u);
  x.run_for(1.05);  // the first move is done: the 3rd and everything after it go in…
  EXPECT_EQ(x.machine.accepted_blocks(), program.size() - 1) << "…but M30, which waits for the queue to drain";
  x.run_for(5.0);
  EXPECT_EQ(x.executed_lines(), program);
  EXPECT_FALSE(x.machine.alarm().has_value());
}

}  // namespace
}  // namespace lamina::sim
