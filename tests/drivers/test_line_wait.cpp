// grbl_line_wait: which program lines a grblHAL answers only after the motion before them
// (gcode.c: spindle_sync, coolant_sync, mc_dwell, program flow, the stored-offset writes), as
// the streamer's stall rule needs to know.
#include <gtest/gtest.h>

#include "lamina/drivers/line_wait.hpp"

namespace lamina::drivers {
namespace {

TEST(LineWait, OrdinaryMotionIsAnsweredWhenQueued) {
  for (const char* line : {"G1X10Y20F1800", "G0Z10", "G93G1X1.5A2C3F900", "(CONTOUR 3 L1-2 OUTLINE 0)", "G21G90G94G17",
                           "X-1.5Y+2", "N120G1X1", "G54", "G92X0"}) {
    const LineWait w = grbl_line_wait(line);
    EXPECT_FALSE(w.syncs) << line;
    EXPECT_EQ(w.dwell_s, 0) << line;
  }
}

TEST(LineWait, DwellSyncsAndCarriesItsSeconds) {
  EXPECT_TRUE(grbl_line_wait("G4P1").syncs);
  EXPECT_DOUBLE_EQ(grbl_line_wait("G4P1").dwell_s, 1.0);
  EXPECT_DOUBLE_EQ(grbl_line_wait("g4 p2.5").dwell_s, 2.5) << "either case, spaces inside words";
  EXPECT_DOUBLE_EQ(grbl_line_wait("G04 P0.05").dwell_s, 0.05) << "leading zero in the code";
  EXPECT_DOUBLE_EQ(grbl_line_wait("P3G4").dwell_s, 3.0) << "word order is free";
  EXPECT_DOUBLE_EQ(grbl_line_wait("G4P1(P9)").dwell_s, 1.0) << "comments are not words";
  EXPECT_DOUBLE_EQ(grbl_line_wait("G4P1;P9").dwell_s, 1.0);
  EXPECT_FALSE(grbl_line_wait("(G4P1)").syncs);
  EXPECT_FALSE(grbl_line_wait("G40").syncs) << "G40 is not G4";
  EXPECT_FALSE(grbl_line_wait("G41.1").syncs);
}

TEST(LineWait, JetCoolantProgramFlowAndStoredOffsetsSync) {
  for (const char* line : {"M3", "M03", "M4", "M5", "M3S1000", "S500", "M7", "M8", "M9", "M0", "M1", "M2", "M30", "M6T1",
                           "M66P0L3Q5", "G10L2P1X0", "G10L20P1X0", "G28.1", "G30.1"}) {
    const LineWait w = grbl_line_wait(line);
    EXPECT_TRUE(w.syncs) << line;
    EXPECT_EQ(w.dwell_s, 0) << line;
  }
  EXPECT_FALSE(grbl_line_wait("M62P1").syncs) << "a digital output synchronised with motion: queued";
  EXPECT_FALSE(grbl_line_wait("M300").syncs);
  EXPECT_FALSE(grbl_line_wait("G10L1P1Z5").syncs) << "tool table, not a stored offset";
}

TEST(LineWait, UnreadableTextIsAnOrdinaryLine) {
  // The controller refuses it with error:N at once; nothing to wait for.
  EXPECT_FALSE(grbl_line_wait("G4P1.2.3").syncs);
  EXPECT_FALSE(grbl_line_wait("M").syncs);
  EXPECT_FALSE(grbl_line_wait("").syncs);
  EXPECT_DOUBLE_EQ(grbl_line_wait("G4P1(unclosed P9").dwell_s, 1.0) << "an unclosed comment runs to the end";
}

}  // namespace
}  // namespace lamina::drivers
