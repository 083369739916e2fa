// What the simulated jet cuts out of a sheet (as_cut.hpp, issue 20), on programs written by hand
// whose answer is known: a square cut vertically leaves its inside smaller by the kerf at each
// depth (the taper: narrower at the bottom); a jet tilted across the travel cuts wider by
// 1 / cos(tilt); the trail-back cuts a square's corners at the bottom and not at the top; and the
// pieces a program frees are all found, a hole's slug among them, the skeleton not.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>

#include "as_cut.hpp"
#include "program_run.hpp"

namespace lamina::sim {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

// A square of `side` mm from (x0, y0), cut counter-clockwise at `feed` mm/min with the head tilted
// by `a_deg` (C 0), from a lead-in on the left, over its start by 3 mm and out.
std::string square_program(double x0, double y0, double side, double feed, double a_deg = 0.0) {
  std::string p = "G21G90G94\n";
  p += fmt::format("G0X{:.4f}Y{:.4f}Z0A{:.3f}C0\nM3\n", x0 - 4, y0 + side / 2, a_deg);
  p += fmt::format("G1X{:.4f}Y{:.4f}F{:.1f}\n", x0, y0 + side / 2, feed);
  p += fmt::format("G1X{:.4f}Y{:.4f}\n", x0, y0);
  p += fmt::format("G1X{:.4f}Y{:.4f}\n", x0 + side, y0);
  p += fmt::format("G1X{:.4f}Y{:.4f}\n", x0 + side, y0 + side);
  p += fmt::format("G1X{:.4f}Y{:.4f}\n", x0, y0 + side);
  // Over the start again before leaving: a jet that lags has not cut the bottom there yet.
  p += fmt::format("G1X{:.4f}Y{:.4f}\n", x0, y0 + side / 2 - 3);
  p += fmt::format("G1X{:.4f}Y{:.4f}\nM5\n", x0 - 4, y0 + side / 2 - 3);
  return p;
}

double ring_area(const Ring& r) {
  double twice = 0.0;
  for (std::size_t i = 0; i < r.size(); ++i) {
    const auto& a = r[i];
    const auto& b = r[(i + 1) % r.size()];
    twice += a[0] * b[1] - b[0] * a[1];
  }
  return 0.5 * twice;
}

double piece_area(const AsCutPiece& p) {
  double a = 0.0;
  for (const Ring& r : p.rings) a += ring_area(r);
  return a;
}

JetPhysics no_drag() {
  JetPhysics jet;
  jet.lag_max_deg = 0.0;
  return jet;
}

MachineConfig machine() {
  MachineConfig m;
  m.soft_limits = false;
  return m;
}

TEST(AsCut, AVerticalSquareLeavesItsInsideSmallerByTheKerfAtEveryDepth) {
  const JetPhysics jet = no_drag();
  AsCutParams params;
  params.sheet_thickness_mm = 10.0;
  params.sections = 4;
  const double feed = 600.0;  // mm/min
  auto cut = cut_program(square_program(10, 10, 20, feed), machine(), HeadGeometry{}, jet, params);
  ASSERT_TRUE(cut) << cut.error();
  ASSERT_EQ(cut->sections.size(), 4u);
  const CutWall wall = cut_wall(jet, 10.0, feed / 60.0);
  ASSERT_GT(wall.bottom_width_mm, 0.0);
  ASSERT_LT(wall.bottom_width_mm, wall.top_width_mm) << "this feed tapers the usual way";
  double last_area = 0.0;
  for (const AsCutSection& s : cut->sections) {
    ASSERT_EQ(s.pieces.size(), 1u) << "the square's inside, nothing else, at " << s.depth_mm << " mm";
    ASSERT_EQ(s.pieces[0].rings.size(), 1u);
    const double kerf = wall.top_width_mm - 2.0 * s.depth_mm * wall.wall_lean_tan;
    // Half widths are rounded to width_step_mm (0.0005 mm): the kerf within 0.0005, the area
    // within 2 · 19.5 · 0.0005 ≈ 0.02 mm².
    EXPECT_NEAR(piece_area(s.pieces[0]), (20.0 - kerf) * (20.0 - kerf), 0.02) << s.depth_mm << " mm down";
    EXPECT_GT(piece_area(s.pieces[0]), last_area) << "the kerf narrows downwards";
    last_area = piece_area(s.pieces[0]);
  }
}

TEST(AsCut, AJetTiltedAcrossTheTravelCutsWiderByOneOverCosTilt) {
  const JetPhysics jet = no_drag();
  AsCutParams params;
  params.sheet_thickness_mm = 10.0;
  params.sections = 1;
  HeadGeometry head;
  head.rtcp = true;  // X Y Z are the tip's
  // A 30° about the head's x (C 0): the jet leans in y-z, so the sides along x are cut with the
  // tilt across them, those along y with it along them.
  auto cut = cut_program(square_program(10, 10, 20, 600.0, 30.0), machine(), head, jet, params);
  ASSERT_TRUE(cut) << cut.error();
  ASSERT_EQ(cut->sections[0].pieces.size(), 1u);
  const CutWall wall = cut_wall(jet, 10.0 / std::cos(30 * kDeg), 10.0);
  const double depth = cut->sections[0].depth_mm, along = depth / std::cos(30 * kDeg);
  const double half = 0.5 * wall.top_width_mm - along * wall.wall_lean_tan;
  double x_lo = 1e9, x_hi = -1e9, y_lo = 1e9, y_hi = -1e9;
  for (const auto& p : cut->sections[0].pieces[0].rings[0]) {
    x_lo = std::min(x_lo, p[0]);
    x_hi = std::max(x_hi, p[0]);
    y_lo = std::min(y_lo, p[1]);
    y_hi = std::max(y_hi, p[1]);
  }
  // Below the top the square is shifted along y by depth·tan 30° (the jet leans), and its walls
  // across y are in by half / cos 30°.
  const double shift = depth * std::tan(30 * kDeg);
  EXPECT_NEAR(y_lo, 10.0 + shift + half / std::cos(30 * kDeg), 0.005);
  EXPECT_NEAR(y_hi, 30.0 + shift - half / std::cos(30 * kDeg), 0.005);
  EXPECT_NEAR(x_lo, 10.0 + half, 0.005);
  EXPECT_NEAR(x_hi, 30.0 - half, 0.005);
}

TEST(AsCut, TheTrailBackCutsTheCornersAtTheBottomNotAtTheTop) {
  JetPhysics jet;  // with its drag
  AsCutParams params;
  params.sheet_thickness_mm = 10.0;
  params.sections = 5;
  const double feed = 1200.0;
  auto cut = cut_program(square_program(10, 10, 20, feed), machine(), HeadGeometry{}, jet, params);
  ASSERT_TRUE(cut) << cut.error();
  const CutWall wall = cut_wall(jet, 10.0, feed / 60.0);
  ASSERT_GT(wall.trail_back_mm, 1.0) << "a jet that lags";
  std::vector<double> loss;  // area the drag took, against the square less the kerf there
  for (const AsCutSection& s : cut->sections) {
    ASSERT_EQ(s.pieces.size(), 1u);
    const double kerf = wall.top_width_mm - 2.0 * s.depth_mm * wall.wall_lean_tan;
    loss.push_back((20.0 - kerf) * (20.0 - kerf) - piece_area(s.pieces[0]));
  }
  // The drag at depth d is L·d/t; each corner loses about (1 − π/4)·(L d/t)² … of the order of
  // its square. Near the top almost nothing, at the bottom a visible corner, growing on the way.
  const double lag_bottom = wall.trail_back_mm * cut->sections.back().depth_mm / 10.0;
  EXPECT_LT(loss.front(), 0.05);
  EXPECT_GT(loss.back(), 0.5 * lag_bottom * lag_bottom) << "four corners cut inside";
  for (std::size_t k = 1; k < loss.size(); ++k) EXPECT_GT(loss[k], loss[k - 1]) << k;
}

TEST(AsCut, EveryPieceAProgramFreesIsFoundTheSkeletonIsNot) {
  const JetPhysics jet = no_drag();
  AsCutParams params;
  params.sections = 2;
  // A 30 mm square with a 10 mm square hole (its slug a piece of its own), and beside it another part.
  std::string program = square_program(15, 15, 10, 600.0) + square_program(10, 10, 20, 600.0) + square_program(50, 10, 20, 600.0);
  auto cut = cut_program(program, machine(), HeadGeometry{}, jet, params);
  ASSERT_TRUE(cut) << cut.error();
  for (const AsCutSection& s : cut->sections) {
    ASSERT_EQ(s.pieces.size(), 3u) << "the part with its hole, the hole's slug, the other part";
    int with_hole = 0;
    for (const AsCutPiece& p : s.pieces) with_hole += p.rings.size() == 2 ? 1 : 0;
    EXPECT_EQ(with_hole, 1);
    for (const AsCutPiece& p : s.pieces) {
      EXPECT_GT(ring_area(p.rings[0]), 0.0) << "outer rings counter-clockwise";
      for (std::size_t r = 1; r < p.rings.size(); ++r) EXPECT_LT(ring_area(p.rings[r]), 0.0) << "holes clockwise";
    }
  }
}

TEST(AsCut, TheRecordSaysWhichProgramItWasCutFrom) {
  const std::string a = square_program(10, 10, 20, 600.0), b = square_program(10, 10, 20, 601.0);
  EXPECT_NE(program_fingerprint(a), program_fingerprint(b));
  EXPECT_EQ(program_fingerprint(""), "cbf29ce484222325") << "FNV-1a's offset basis";
  EXPECT_EQ(program_fingerprint("a"), "af63dc4c8601ec8c") << "FNV-1a 64 of \"a\"";
  AsCutParams params;
  params.sections = 1;
  auto cut = cut_program(a, machine(), HeadGeometry{}, no_drag(), params);
  ASSERT_TRUE(cut);
  const auto json = as_cut_json(*cut, "sheet-1.nc", a);
  EXPECT_EQ(json["format"], "lamina-sim as-cut 1");
  EXPECT_EQ(json["program_fnv1a64"], program_fingerprint(a));
  EXPECT_EQ(json["sections"][0]["pieces"].size(), 1u);
  params.sections = 0;
  EXPECT_FALSE(cut_program(a, machine(), HeadGeometry{}, no_drag(), params));
  params.sections = 1;
  auto refused = cut_program("G1X10F100\nG999\n", machine(), HeadGeometry{}, no_drag(), params);
  ASSERT_FALSE(refused);
  EXPECT_NE(refused.error().find("line 2"), std::string::npos) << refused.error();
}

}  // namespace
}  // namespace lamina::sim
