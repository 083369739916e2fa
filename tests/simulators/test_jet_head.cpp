// The simulated machine's own head (jet_head.hpp, issue 20): where the jet's tip and axis are for
// the axes it executes, written without Lamina's kinematics. Checked by hand at known poses, and
// against a program Lamina posted: a calibration coupon run through the simulated controller cuts
// every slot on the sheet's top face, its tilted slots at 30°, at the y the coupon put them.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <numbers>

#include "exec_log.hpp"
#include "jet_head.hpp"
#include "jet_physics.hpp"
#include "machine.hpp"
#include "sim_options.hpp"

namespace lamina::sim {
namespace {

constexpr double kRadPerDeg = std::numbers::pi / 180.0;

TEST(JetHead, KnownPoses) {
  const HeadGeometry head;  // pivot 150, signs +1, no offset, pivot coordinates
  JetPose p = jet_pose({10, 20, 0, 0, 37}, head);
  EXPECT_NEAR(p.tip_mm[0], 10, 1e-12);
  EXPECT_NEAR(p.tip_mm[1], 20, 1e-12);
  EXPECT_NEAR(p.tip_mm[2], 0, 1e-12);
  EXPECT_NEAR(p.axis[2], 1, 1e-12) << "A = 0: vertical whatever C";
  // A = 30 at C = 0 leans the jet towards −Y (machine.toml: "C where a positive A leans the jet
  // towards −Y"); the pivot is 150 mm up the axis, so the program's point is 75 mm off in y and
  // 20.1 mm low in z.
  p = jet_pose({18, 0, -20.096, 30, 0}, head);
  EXPECT_NEAR(p.axis[0], 0, 1e-12);
  EXPECT_NEAR(p.axis[1], -0.5, 1e-12);
  EXPECT_NEAR(p.axis[2], std::cos(30 * kRadPerDeg), 1e-12);
  EXPECT_NEAR(p.tip_mm[1], 75, 1e-9);
  EXPECT_NEAR(p.tip_mm[2], 0, 1e-3);
  // C = 90 turns the lean towards +X; a negative a_sign reverses it.
  p = jet_pose({0, 0, 0, 30, 90}, head);
  EXPECT_NEAR(p.axis[0], 0.5, 1e-12);
  EXPECT_NEAR(p.axis[1], 0, 1e-12);
  HeadGeometry flipped;
  flipped.a_sign = -1;
  EXPECT_NEAR(jet_pose({0, 0, 0, 30, 0}, flipped).axis[1], 0.5, 1e-12);
  // With RTCP the program's point is the tip.
  HeadGeometry rtcp;
  rtcp.rtcp = true;
  p = jet_pose({5, 6, 7, 45, 10}, rtcp);
  EXPECT_EQ(p.tip_mm, (std::array<double, 3>{5, 6, 7}));
}

TEST(JetHead, ACouponLaminaPostedCutsWhereItSays) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "lamina-sim-jet-head";
  std::filesystem::remove_all(dir);
  const std::string command = std::string(LAMINA_CLI) + " calibrate coupon --material 'aluminium 6061-T6' --thickness 10 --out '" +
                              dir.string() + "' > /dev/null 2>&1";
  ASSERT_EQ(std::system(command.c_str()), 0) << command;
  MachineConfig config;
  config.planner_blocks = 100000;  // the whole program queued at once: only where the jet goes matters here
  Machine machine(config);
  std::ifstream program(dir / "coupon.nc");
  for (std::string line; std::getline(program, line);) ASSERT_EQ(machine.submit_line(line, 0), GrblStatus::ok) << line;
  machine.advance(1e6);
  const HeadGeometry head;  // config/machine.toml's: pivot 150 mm, +1, +1, 0°, no RTCP
  std::map<long, double> tilt_at_y;  // slot y (mm, rounded) → its cut's tilt
  int cuts = 0;
  for (const auto& event : machine.take_events()) {
    const auto* b = std::get_if<ExecutedBlock>(&event);
    if (!b || !b->jet || b->start == b->end) continue;  // the pierce dwells stand still
    const JetPose start = jet_pose(b->start, head), end = jet_pose(b->end, head);
    EXPECT_NEAR(end.tip_mm[2], 0.0, 0.01) << b->line << ": the tip on the top face";
    if (std::abs(end.tip_mm[0] - start.tip_mm[0]) < 39.0) continue;  // lead-ins and lead-outs
    ++cuts;
    EXPECT_NEAR(end.tip_mm[1], start.tip_mm[1], 1e-3) << b->line << ": a straight slot along x";
    tilt_at_y[std::lround(end.tip_mm[1])] = std::acos(end.axis[2]) / kRadPerDeg;
  }
  EXPECT_EQ(cuts, 10);
  ASSERT_EQ(tilt_at_y.size(), 10u);
  // Twelve apart from 15 mm: the five vertical slots first, then the five at 30°.
  long y = 15;
  for (const auto& [slot_y, tilt] : tilt_at_y) {
    EXPECT_EQ(slot_y, y);
    EXPECT_NEAR(tilt, y < 75 ? 0.0 : 30.0, 0.01) << "slot at y " << slot_y;
    y += 12;
  }
  std::filesystem::remove_all(dir);
}

// The simulated jet's own form: its taper reverses where k·r^n = k0, its trail-back saturates at
// h·tan φ_max, its top widens when slow, and a jet past its separation speed does not cut through.
TEST(JetPhysics, TheSimulatedJetsShape) {
  const JetPhysics jet;  // v_s(10 mm) 25 mm/s
  const double free_ratio = std::pow(jet.taper_offset / jet.taper_gain, 1.0 / jet.taper_exponent);
  const CutWall balanced = cut_wall(jet, 10.0, free_ratio * 25.0);
  EXPECT_NEAR(balanced.top_width_mm, balanced.bottom_width_mm, 1e-9);
  const CutWall slow = cut_wall(jet, 10.0, 0.5 * free_ratio * 25.0), fast = cut_wall(jet, 10.0, 0.8 * 25.0);
  EXPECT_GT(slow.bottom_width_mm, slow.top_width_mm) << "reversed";
  EXPECT_LT(fast.bottom_width_mm, fast.top_width_mm) << "V";
  EXPECT_GT(slow.top_width_mm, fast.top_width_mm) << "wider when slow";
  EXPECT_LT(slow.trail_back_mm, fast.trail_back_mm);
  EXPECT_NEAR(cut_wall(jet, 10.0, 100 * 25.0).trail_back_mm, 10.0 * std::tan(jet.lag_max_deg * kRadPerDeg), 1e-6) << "saturates";
  EXPECT_EQ(cut_wall(jet, 10.0, 3 * 25.0).bottom_width_mm, 0.0) << "not through";
  // A longer path is slower to separate: the same feed is a larger ratio there.
  EXPECT_GT(cut_wall(jet, 20.0, 10.0).trail_back_mm, 2 * cut_wall(jet, 10.0, 10.0).trail_back_mm);
}

// The machine file's head_* keys give the head, and the execution log then says where the jet is.
TEST(JetHead, TheMachineFileGivesItAndTheLogSaysWhereTheJetIs) {
  const std::filesystem::path file = std::filesystem::temp_directory_path() / "lamina-sim-head.toml";
  std::ofstream(file) << "head_pivot_mm = 120\nhead_c_sign = -1\n";
  SimOptions options;
  apply_machine_file(file.string(), options);
  ASSERT_TRUE(options.head);
  EXPECT_EQ(options.head->pivot_mm, 120);
  EXPECT_EQ(options.head->c_sign, -1);
  EXPECT_EQ(options.head->a_sign, 1);
  ExecutedBlock block;
  block.end = {0, 0, 0, 30, 90};
  const auto record = to_json_record(block, options.head);
  ASSERT_TRUE(record.contains("tip") && record.contains("axis")) << record.dump();
  EXPECT_NEAR(record["axis"][0].get<double>(), -0.5, 1e-12) << "c_sign −1 turns C = 90 the other way";
  EXPECT_FALSE(to_json_record(block).contains("tip")) << "no head: the log as before";

  std::ofstream(file) << "head_a_sign = 2\n";
  SimOptions bad;
  try {
    apply_machine_file(file.string(), bad);
    ADD_FAILURE() << "a sign of 2 was taken";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("head_a_sign"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(":1"), std::string::npos) << "the line: " << e.what();
  }
  std::filesystem::remove(file);
}

}  // namespace
}  // namespace lamina::sim
