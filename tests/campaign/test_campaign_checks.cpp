// The campaign's oracle on logs written by hand: each check passes a good run and names what is
// wrong in a bad one (a finished contour cut twice, a contour skipped or cut dry, the jet left
// on at a standstill). A check that cannot fail would make the campaign's "0 violations" empty.
#include <gtest/gtest.h>

#include "campaign_checks.hpp"

namespace lamina::campaign {
namespace {

// Two contours, each pierced, cut with two moves and closed.
const std::vector<std::string> kProgram{
    "G21G90G94",          // 1
    "(CONTOUR 1 outer)",  // 2
    "G0X0Y0",             // 3
    "M3",                 // 4
    "G4P0.5",             // 5
    "G1X10Y0F1800",       // 6
    "G1X10Y10",           // 7
    "M5",                 // 8
    "(CONTOUR 2 hole)",   // 9
    "G0X20Y0",            // 10
    "M3",                 // 11
    "G4P0.5",             // 12
    "G1X30Y0",            // 13
    "G1X30Y10",           // 14
    "M5",                 // 15
    "M2",                 // 16
};

// A log built line by line: each move takes 1 s, the water flows while the M-code is on.
class LogWriter {
 public:
  void run(std::size_t from, std::size_t to) {  // program lines [from, to], 1-based
    for (std::size_t i = from; i <= to; ++i) block(kProgram[i - 1]);
  }
  void block(const std::string& line, bool completed = true) {
    const bool move = line.find_first_of("XY") != std::string::npos;
    const bool dwell = line.rfind("G4", 0) == 0;
    if (line == "M3") jet(true);
    if (line == "M5" || line == "M2") jet(false);
    state(move || dwell ? "run" : state_);
    const double t0 = t_;
    if (move || dwell) t_ += 1;
    Block b{line, completed, jet_, move, t0, t_};
    log.blocks.push_back(b);
  }
  void jet(bool on) {
    jet_ = on;
    flowing(on && consent_);
  }
  void consent(bool on) {  // the PLC's independent path
    consent_ = on;
    flowing(jet_ && consent_);
  }
  void state(const std::string& s) {
    if (s == state_) return;
    state_ = s;
    log.states.push_back({t_, false, s});
  }
  void wait(double s) { t_ += s; }

  MachineLog log;

 private:
  void flowing(bool on) {
    if (log.jet.empty() ? !on : log.jet.back().flowing == on) return;
    log.jet.push_back({t_, on, {}});
  }
  double t_ = 0;
  bool jet_ = false, consent_ = true;
  std::string state_ = "idle";
};

TEST(CampaignContours, AWholeRunCutsEveryContourOnce) {
  LogWriter w;
  w.run(1, 16);
  w.state("idle");
  const ContourCheck c = check_contours_cut_once(kProgram, w.log, true);
  EXPECT_TRUE(c.violations.empty()) << c.violations.front();
  EXPECT_EQ(c.contours, 2u);
  EXPECT_EQ(c.finished, 2u);
  EXPECT_EQ(c.passes, 1u);
}

TEST(CampaignContours, AResumeAtTheCutShortContourIsAllowed) {
  LogWriter w;
  w.run(1, 12);
  w.block("G1X30Y0", false);  // the fault: cut short
  w.jet(false);
  w.state("idle");
  w.block("G21G90G94");  // the resume's set-up, then the contour again from its marker
  w.block("G0Z10");
  w.run(9, 16);
  const ContourCheck c = check_contours_cut_once(kProgram, w.log, true);
  EXPECT_TRUE(c.violations.empty()) << c.violations.front();
  EXPECT_EQ(c.finished, 2u);
  EXPECT_EQ(c.cut_again, 1u);
  EXPECT_EQ(c.passes, 2u);
}

TEST(CampaignContours, AFinishedContourCutAgainIsAViolation) {
  LogWriter w;
  w.run(1, 10);  // contour 1 finished, the daemon died on the way to contour 2
  w.state("idle");
  w.run(2, 16);  // resumed at contour 1: the old min(placed, saved ack) rule
  const ContourCheck c = check_contours_cut_once(kProgram, w.log, true);
  ASSERT_EQ(c.violations.size(), 1u);
  EXPECT_NE(c.violations[0].find("(CONTOUR 1 outer) (line 2) was cut again in pass 2"), std::string::npos)
      << c.violations[0];
}

TEST(CampaignContours, AFinishedContourRunAgainDryIsNotACut) {
  LogWriter w;
  w.run(1, 10);
  w.state("idle");
  w.consent(false);  // the PLC keeps the water off: the moves are air
  w.run(2, 8);
  w.consent(true);
  w.run(9, 16);
  const ContourCheck c = check_contours_cut_once(kProgram, w.log, true);
  EXPECT_TRUE(c.violations.empty()) << c.violations.front();
}

TEST(CampaignContours, AContourSkippedOrCutDryIsAViolation) {
  LogWriter skipped;
  skipped.run(1, 6);  // halfway through contour 1
  skipped.state("idle");
  skipped.run(9, 16);  // resumed at contour 2
  ContourCheck c = check_contours_cut_once(kProgram, skipped.log, true);
  ASSERT_EQ(c.violations.size(), 1u);
  EXPECT_NE(c.violations[0].find("(CONTOUR 1 outer) (line 2) was never cut whole"), std::string::npos) << c.violations[0];
  EXPECT_NE(c.violations[0].find("line 7"), std::string::npos) << c.violations[0];

  // The dry tail: the water went off in contour 1's last move, the machine coasted on into
  // contour 2's marker, and the resume started there.
  LogWriter tail;
  tail.run(1, 6);
  tail.consent(false);
  tail.run(7, 9);
  tail.state("hold");
  tail.consent(true);
  tail.run(9, 16);
  c = check_contours_cut_once(kProgram, tail.log, true);
  ASSERT_EQ(c.violations.size(), 1u);
  EXPECT_NE(c.violations[0].find("line 7 never ran with the water on"), std::string::npos) << c.violations[0];
  // The same log, the sheet not reported done: nothing is owed yet.
  EXPECT_TRUE(check_contours_cut_once(kProgram, skipped.log, false).violations.empty());
}

TEST(CampaignContours, ALineOutsideTheProgramThatCutsIsAViolation) {
  LogWriter w;
  w.run(1, 8);
  w.block("M3");
  w.block("G1X5Y5");  // a set-up that opens the jet and moves: not the program's
  w.block("M5");
  w.run(9, 16);
  const ContourCheck c = check_contours_cut_once(kProgram, w.log, true);
  ASSERT_FALSE(c.violations.empty());
  EXPECT_NE(c.violations[0].find("'G1X5Y5'"), std::string::npos) << c.violations[0];
}

TEST(CampaignJet, APierceDwellIsNotAStandstill) {
  LogWriter w;
  w.run(1, 16);
  w.state("idle");
  const JetCheck j = check_jet_off_at_standstill(w.log, 0.1, 1.5);
  EXPECT_TRUE(j.violations.empty()) << j.violations.front();
  EXPECT_EQ(j.standstills_with_jet, 0u);
  EXPECT_EQ(j.restarts_in_kerf, 0u);
}

TEST(CampaignJet, TheJetOnAHeldMachineIsTimedInWallSeconds) {
  LogWriter w;
  w.run(1, 6);
  w.state("hold_pending");  // decelerating: still cutting
  w.wait(0.2);
  w.state("hold");
  w.wait(1.0);  // 1 s simulated on the held machine with the water on
  w.consent(false);
  w.wait(5);
  w.consent(true);
  w.state("run");
  w.run(7, 16);
  w.state("idle");
  // At --time-scale 20, 1 s simulated is 50 ms of wall time: within 100 ms.
  w.log.initial_scale = 20;
  JetCheck j = check_jet_off_at_standstill(w.log, 0.1, 1.5);
  EXPECT_TRUE(j.violations.empty()) << j.violations.front();
  EXPECT_EQ(j.standstills_with_jet, 1u);
  EXPECT_NEAR(j.worst_wall_s, 0.05, 1e-9);
  // At --time-scale 5 it is 200 ms.
  w.log.initial_scale = 5;
  j = check_jet_off_at_standstill(w.log, 0.1, 1.5);
  ASSERT_EQ(j.violations.size(), 1u);
  EXPECT_NE(j.violations[0].find("200 ms (wall) on a machine standing in hold"), std::string::npos) << j.violations[0];
  // Slowed to real time (control `time-scale 1`) just before the hold: 1 s of wall time.
  w.log.initial_scale = 20;
  w.log.scales = {{3.0, 1.0}};
  j = check_jet_off_at_standstill(w.log, 0.1, 1.5);
  ASSERT_EQ(j.violations.size(), 1u);
  EXPECT_NE(j.violations[0].find("1000 ms (wall)"), std::string::npos) << j.violations[0];
}

TEST(CampaignJet, AJetLeftOnAtTheEndOfTheLogIsCounted) {
  LogWriter w;
  w.run(1, 6);
  w.state("idle");  // starved, the M-code on, and nobody came
  w.block("G4P0.5");
  w.state("idle");
  w.wait(3);
  w.block("(CONTOUR 9 never)");
  const JetCheck j = check_jet_off_at_standstill(w.log, 0.1, 1.5);
  ASSERT_EQ(j.violations.size(), 1u) << j.standstills_with_jet;
  EXPECT_NE(j.violations[0].find("standing in idle"), std::string::npos) << j.violations[0];
}

// A resume from a hold: the jet re-opens in the kerf, the motion follows after the
// stabilisation time. Allowed within the restart limit; a jet opened and closed again on a
// machine that never moved is not a restart.
TEST(CampaignJet, TheJetReopenedInTheKerfBeforeTheMotionIsARestart) {
  LogWriter w;
  w.run(1, 6);
  w.state("hold");
  w.consent(false);  // off as the hold completed
  w.wait(3);
  w.consent(true);  // the operator's resume
  w.wait(1.0);
  w.state("run");
  w.run(7, 16);
  w.state("idle");
  JetCheck j = check_jet_off_at_standstill(w.log, 0.1, 1.5);
  EXPECT_TRUE(j.violations.empty()) << j.violations.front();
  EXPECT_EQ(j.restarts_in_kerf, 1u);
  EXPECT_NEAR(j.worst_restart_wall_s, 1.0, 1e-9);
  j = check_jet_off_at_standstill(w.log, 0.1, 0.5);
  ASSERT_EQ(j.violations.size(), 1u);
  EXPECT_NE(j.violations[0].find("before it moved on"), std::string::npos) << j.violations[0];

  LogWriter never_moved;
  never_moved.run(1, 6);
  never_moved.state("hold");
  never_moved.consent(false);
  never_moved.wait(1);
  never_moved.consent(true);  // opened on the held machine …
  never_moved.wait(1.0);
  never_moved.consent(false);  // … and closed again, no motion
  never_moved.wait(1);
  j = check_jet_off_at_standstill(never_moved.log, 0.1, 1.5);
  ASSERT_EQ(j.violations.size(), 1u);
  EXPECT_NE(j.violations[0].find("1000 ms (wall) on a machine standing in hold"), std::string::npos) << j.violations[0];
}

}  // namespace
}  // namespace lamina::campaign
