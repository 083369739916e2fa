// Resume points from the program text and the controller's planner occupancy.
#include <gtest/gtest.h>

#include "lamina/drivers/resume_point.hpp"

namespace lamina::drivers {
namespace {

const std::vector<std::string> kProgram{
    "(KNOB SHEET 1)",                              // 0
    "G21G90G94G17",                                // 1
    "G0X0Y0Z10A0C0",                               // 2
    "(CONTOUR 0 L16-1 OUTLINE 1 PASS 0 HOLE FREES)",  // 3
    "G0X43.5Y33.8Z10A0C0",                         // 4
    "Z0",                                          // 5
    "M3",                                          // 6
    "G4P1",                                        // 7
    "G1X43.3Y36.8F5802",                           // 8
    "X43.0Y36.8",                                  // 9
    "M5",                                          // 10
    "G0Z10",                                       // 11
    "(CONTOUR 1 L16-1 OUTLINE 0 PASS 0 FREES)",    // 12
    "G0X42.8Y58.0Z12.5A0C-358",                    // 13
    "Z0",                                          // 14
    "M3",                                          // 15
    "G93G1X50Y60A10C-350F600",                     // 16
    "G94",                                         // 17
    "G1X51Y60F5802",                               // 18
    "M5",                                          // 19
    "M30",                                         // 20
};

TEST(ResumePoint, PlannerBlocksAreMotionAndDwellLinesOnly) {
  EXPECT_TRUE(takes_planner_block("G0X1"));
  EXPECT_TRUE(takes_planner_block("Z0"));
  EXPECT_TRUE(takes_planner_block("G4P1"));
  EXPECT_TRUE(takes_planner_block("G93G1X50Y60A10C-350F600"));
  EXPECT_FALSE(takes_planner_block("M3"));
  EXPECT_FALSE(takes_planner_block("G94"));
  EXPECT_FALSE(takes_planner_block("G21G90G94G17"));
  EXPECT_FALSE(takes_planner_block("(CONTOUR 1 X5 Y5)")) << "words in a comment do not count";
  EXPECT_FALSE(takes_planner_block("; G0 X5"));
  EXPECT_FALSE(takes_planner_block("F600"));
}

TEST(ResumePoint, FirstUnfinishedLineWalksBackOverQueuedBlocks) {
  // 19 lines acknowledged (through "G1X51…" at 18), 3 blocks queued: 18, 16, 14 → 14 is first.
  EXPECT_EQ(first_unfinished_line(kProgram, 19, 3), 14u);
  // One block queued: the last motion line (18); the G94 and M-codes before it have run.
  EXPECT_EQ(first_unfinished_line(kProgram, 19, 1), 18u);
  // Nothing queued: everything acknowledged has run.
  EXPECT_EQ(first_unfinished_line(kProgram, 12, 0), 12u);
  // More queued than there are blocks: the top.
  EXPECT_EQ(first_unfinished_line(kProgram, 10, 50), 2u) << "the first block line";
}

TEST(ResumePoint, RestartsAtTheContourMarkerWithSetUpAndRetract) {
  const auto plan = plan_resume(kProgram, 16);
  ASSERT_TRUE(plan) << plan.error().message;
  EXPECT_EQ(plan->restart_index, 12u);
  EXPECT_EQ(plan->contour, 1);
  const std::vector<std::string> preamble{"G21G90G94G17", "G94", "G0Z12.5"};
  EXPECT_EQ(plan->preamble, preamble) << "modal set-up, inverse time off, retract to the contour's rapid height";
  // Stopped on the marker itself: contour 0 had finished, restart at contour 1.
  EXPECT_EQ(plan_resume(kProgram, 12)->restart_index, 12u);
  // Stopped in contour 0 after its last cut, before its jet-off (10) or its retract (11): the
  // contour is finished. It used to restart at contour 0 and cut it twice (the fault campaign).
  EXPECT_EQ(plan_resume(kProgram, 11)->restart_index, 12u);
  EXPECT_EQ(plan_resume(kProgram, 10)->restart_index, 12u);
  EXPECT_EQ(plan_resume(kProgram, 10)->contour, 1);
  // Its last cut not finished: the contour again.
  EXPECT_EQ(plan_resume(kProgram, 9)->restart_index, 3u);
  EXPECT_EQ(plan_resume(kProgram, 7)->restart_index, 3u) << "the pierce";
  // The last contour's cut done: go on after it (jet off, program end), not into it again.
  EXPECT_EQ(plan_resume(kProgram, 19)->restart_index, 19u);
  EXPECT_EQ(plan_resume(kProgram, 18)->restart_index, 12u);
}

TEST(ResumePoint, BeforeTheFirstContourStartsOverAndWithoutMarkersRefuses) {
  const auto top = plan_resume(kProgram, 2);
  ASSERT_TRUE(top);
  EXPECT_EQ(top->restart_index, 0u);
  EXPECT_TRUE(top->preamble.empty());
  const std::vector<std::string> bare{"G21", "G0X1", "G1X2F100", "G1X3"};
  const auto refused = plan_resume(bare, 2);
  ASSERT_FALSE(refused);
  EXPECT_EQ(refused.error().code, LinkErrorCode::bad_request);
  EXPECT_NE(refused.error().message.find("CONTOUR"), std::string::npos);
  EXPECT_FALSE(plan_resume(kProgram, 99));
}

}  // namespace
}  // namespace lamina::drivers
