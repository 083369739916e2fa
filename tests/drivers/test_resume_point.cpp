// Resume points from the program, its map (the post's, or its markers') and the controller's
// planner occupancy.
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

std::expected<ResumePlan, LinkError> resume_at(const std::vector<std::string>& program, std::size_t line) {
  return plan_resume(program, program_map_from_markers(program), line);
}

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
  const auto plan = resume_at(kProgram, 16);
  ASSERT_TRUE(plan) << plan.error().message;
  EXPECT_EQ(plan->restart_index, 12u);
  EXPECT_EQ(plan->contour, 1);
  const std::vector<std::string> preamble{"G21G90G94G17", "G94", "G0Z12.5"};
  EXPECT_EQ(plan->preamble, preamble) << "modal set-up, inverse time off, retract to the contour's rapid height";
  // Stopped on the marker itself: contour 0 had finished, restart at contour 1.
  EXPECT_EQ(resume_at(kProgram, 12)->restart_index, 12u);
  // Stopped in contour 0 after its last cut, before its jet-off (10) or its retract (11): the
  // contour is finished. It used to restart at contour 0 and cut it twice (the fault campaign).
  EXPECT_EQ(resume_at(kProgram, 11)->restart_index, 12u);
  EXPECT_EQ(resume_at(kProgram, 10)->restart_index, 12u);
  EXPECT_EQ(resume_at(kProgram, 10)->contour, 1);
  // Its last cut not finished: the contour again.
  EXPECT_EQ(resume_at(kProgram, 9)->restart_index, 3u);
  EXPECT_EQ(resume_at(kProgram, 7)->restart_index, 3u) << "the pierce";
  // The last contour's cut done: go on after it (jet off, program end), not into it again.
  EXPECT_EQ(resume_at(kProgram, 19)->restart_index, 19u);
  EXPECT_EQ(resume_at(kProgram, 18)->restart_index, 12u);
}

TEST(ResumePoint, BeforeTheFirstContourStartsOverAndWithoutMarkersRefuses) {
  const auto top = resume_at(kProgram, 2);
  ASSERT_TRUE(top);
  EXPECT_EQ(top->restart_index, 0u);
  EXPECT_TRUE(top->preamble.empty());
  const std::vector<std::string> bare{"G21", "G0X1", "G1X2F100", "G1X3"};
  const auto refused = resume_at(bare, 2);
  ASSERT_FALSE(refused);
  EXPECT_EQ(refused.error().code, LinkErrorCode::bad_request);
  EXPECT_NE(refused.error().message.find("CONTOUR"), std::string::npos);
  EXPECT_FALSE(resume_at(kProgram, 99));
}

TEST(ResumePoint, TheMarkersMapEachContourFromItsMarkerToItsLastCut) {
  const ProgramMap map = program_map_from_markers(kProgram);
  EXPECT_EQ(map.setup_end, 3u);
  ASSERT_EQ(map.contours.size(), 2u);
  EXPECT_EQ(map.contours[0].contour, 0);
  EXPECT_EQ(map.contours[0].start_index, 3u);
  EXPECT_EQ(map.contours[0].last_cut_index, 9u) << "the dwell is no cut";
  EXPECT_EQ(map.contours[1].start_index, 12u);
  EXPECT_EQ(map.contours[1].last_cut_index, 18u);
}

// Issue 18: the resume point came from parsing `(CONTOUR ` comments back, so a dialect with other
// comment syntax (Siemens `;`) or other jet M-codes would have had no safe point, or a wrong one.
// With the post's map the program's text is not searched for contours at all.
TEST(ResumePoint, ThePostsMapNeedsNoMarkersNorTheJetsMCodes) {
  const std::vector<std::string> siemens{
      "; KNOB SHEET 1",      // 0
      "G71 G90 G94 G17",     // 1
      "; CONTOUR 0 L1-1",    // 2
      "G0 X10 Y0 Z10",       // 3
      "M62",                 // 4  jet on (a configurable M-code)
      "G1 X20 F500",         // 5
      "G1 X30",              // 6
      "M63",                 // 7  jet off
      "G0 Z10",              // 8
      "; CONTOUR 1 L1-2",    // 9
      "G0 X40 Y0 Z12",       // 10
      "M62",                 // 11
      "G1 X50 F500",         // 12
      "M63",                 // 13
      "M30",                 // 14
  };
  const ProgramMap map{2, {{0, 2, 6}, {1, 9, 12}}};
  auto in_first = plan_resume(siemens, map, 6);
  ASSERT_TRUE(in_first) << in_first.error().message;
  EXPECT_EQ(in_first->restart_index, 2u);
  EXPECT_EQ(in_first->contour, 0);
  EXPECT_EQ(in_first->preamble, (std::vector<std::string>{"G71 G90 G94 G17", "G94", "G0Z10"}));
  auto after_its_cut = plan_resume(siemens, map, 7);
  ASSERT_TRUE(after_its_cut);
  EXPECT_EQ(after_its_cut->restart_index, 9u) << "contour 0's last cut ran: it is not cut twice";
  EXPECT_EQ(after_its_cut->contour, 1);
  EXPECT_EQ(plan_resume(siemens, map, 13)->restart_index, 13u) << "after the last cut: go on to the end";
  // The same program read for markers has none: refused, not resumed somewhere unsafe.
  EXPECT_FALSE(resume_at(siemens, 6));
}

}  // namespace
}  // namespace lamina::drivers
