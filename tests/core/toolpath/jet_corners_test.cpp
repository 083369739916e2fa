// Corner speeds from the jet's trail-back (issue 20, cam/jet_corners.hpp): under a kerf model a
// corner is cut at the feed whose lag keeps the lower jet's chord across the turn within the
// allowance (lag · sin(turn/2) ≤ --corner-error), for the full feed's lag either side of it, and
// at the full feed everywhere else; inside corners of the part may keep the feed instead. Without
// a model the angle heuristic stays, byte for byte.
#include "toolpath_fixture.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace lamina {
namespace {

// Trail-back 0.8 · h_f · r²: at this sheet and feed a lag the corners must slow for.
const KerfModel kCornerKerf{.top_width_mm = 1.0,
                      .top_width_per_ratio_mm = 0.0,
                      .taper_per_ratio = 0.05,
                      .taper_free_ratio = 0.1,
                      .trail_back_factor = 0.8,
                      .trail_back_exponent = 2.0};
constexpr double kCornerHalfSide = 20.0, kHoleHalf = 8.0, kCornerThickness = 5.0, kCornerKerfMm = 1.0;
const Eigen::Vector2d kCornerCentre(100, 50);

// A 40 mm square of 5 mm plate, vertical walls, with (or without) a 16 mm square hole.
Fixture part(bool with_hole) {
  std::vector<LayerOutline> outlines{dev_test::square_outline({0, 0}, kCornerHalfSide, 0, kCornerThickness)};
  if (with_hole) outlines.push_back(dev_test::square_outline({0, 0}, kHoleHalf, 0, kCornerThickness, true, 0));
  return one_part(dev_test::make_layer(0, 0.0, kCornerThickness, outlines), 0.0, kCornerCentre, kCornerKerfMm);
}

ToolpathParams with(InsideCorners inside) {
  ToolpathParams p;
  p.kerf_mm = kCornerKerfMm;
  p.jet_compensation.mode = JetCompensationMode::full;
  p.jet_compensation.kerf_by_material.emplace("aluminium", kCornerKerf);
  p.jet_compensation.corners.inside = inside;
  return p;
}

struct Feeds {
  double full_mm_per_s = 0.0, lag_mm = 0.0;
};

Feeds straight_feed(const ToolpathParams& p) {
  const double feed = *cut_feed_mm_per_s(p.jet, aluminium(), p.feed, kCornerThickness, 0.0);
  const double v_s = *separation_feed_mm_per_s(p.jet, aluminium(), p.feed, kCornerThickness, 0.0);
  return {feed, kerf_at(kCornerKerf, kCornerThickness, feed / v_s)->trail_back_mm};
}

struct CutMove {
  Eigen::Vector3d from, to;
  double feed_mm_per_s = 0.0;
};

// The cut moves of one contour (its overlap past the start included), from its lead-in's end.
std::vector<CutMove> cut_moves(const SheetToolpath& tp, const ToolContour& c) {
  std::vector<CutMove> out;
  std::size_t start = c.first_move;
  while (tp.moves[start].kind != MoveKind::lead_in || tp.moves[start].turn_piece) ++start;
  for (std::size_t i = start + 1; i < c.end_move && tp.moves[i].kind == MoveKind::cut; ++i)
    out.push_back({tp.moves[i - 1].tip_mm, tp.moves[i].tip_mm, tp.moves[i].feed_mm_per_s});
  return out;
}

// Distance from p to the nearest corner of the contour's path: its tips off both mid-lines by
// more than `half`.
double to_corner(const std::vector<CutMove>& moves, const Eigen::Vector3d& p, double half) {
  double best = std::numeric_limits<double>::infinity();
  for (const CutMove& m : moves)
    if ((m.to.head<2>() - kCornerCentre).cwiseAbs().minCoeff() > half) best = std::min(best, (p - m.to).norm());
  return best;
}

TEST(JetCorners, ASquaresCornersAreSlowedToTheAllowanceForTheLagEitherSide) {
  auto f = part(false);
  const ToolpathParams p = with(InsideCorners::slow);
  auto tp = plan_sheet_toolpath(f.plan, f.parts, f.sheet, aluminium(), p);
  ASSERT_TRUE(tp) << tp.error().message;
  const Feeds s = straight_feed(p);
  const double allowance = p.jet_compensation.corners.error_mm, turn = std::numbers::pi / 2;
  ASSERT_GT(s.lag_mm * std::sin(turn / 2), 2 * allowance) << "a lag the corners must slow for";
  // lag ∝ r²: the fraction whose lag gives exactly the allowance across a right angle.
  const double fraction = std::sqrt(allowance / (s.lag_mm * std::sin(turn / 2)));
  ASSERT_GT(fraction, p.jet_compensation.corners.min_fraction);
  const auto moves = cut_moves(*tp, tp->contours.back());
  int slow = 0, full = 0;
  for (const CutMove& m : moves) {
    const double d = to_corner(moves, 0.5 * (m.from + m.to), kCornerHalfSide);
    if (d < s.lag_mm - 1e-6) {
      EXPECT_NEAR(m.feed_mm_per_s, fraction * s.full_mm_per_s, 1e-3 * s.full_mm_per_s) << "within the lag of a corner";
      ++slow;
    } else if (d > s.lag_mm + 1e-6) {
      EXPECT_NEAR(m.feed_mm_per_s, s.full_mm_per_s, 1e-9) << "beyond the lag of every corner: " << m.from.transpose() << " → " << m.to.transpose() << ", " << d << " from a corner";
      ++full;
    }
  }
  EXPECT_GE(slow, 8) << "before and after each of the four corners";
  EXPECT_GE(full, 4) << "the edges between";
  EXPECT_EQ(tp->jet_corners_floored, 0u);
}

// A tighter allowance than the slowest feed allows: the floor holds, and the lines are counted.
TEST(JetCorners, AnAllowanceBeyondTheFloorIsHeldAtItAndCounted) {
  auto f = part(false);
  ToolpathParams p = with(InsideCorners::slow);
  p.jet_compensation.corners.error_mm = 1e-4;
  auto tp = plan_sheet_toolpath(f.plan, f.parts, f.sheet, aluminium(), p);
  ASSERT_TRUE(tp) << tp.error().message;
  const Feeds s = straight_feed(p);
  double slowest = s.full_mm_per_s;
  for (const CutMove& m : cut_moves(*tp, tp->contours.back())) slowest = std::min(slowest, m.feed_mm_per_s);
  EXPECT_NEAR(slowest, p.jet_compensation.corners.min_fraction * s.full_mm_per_s, 1e-9);
  EXPECT_GE(tp->jet_corners_floored, 4u) << "the four corners at least";
}

// The hole's corners are inside corners of the part: `keep` cuts them at the feed (a fillet of
// material stays at their bottom), `slow` slows them as the outside ones, which are slowed either way.
TEST(JetCorners, InsideCornersKeepTheirFeedOnlyWhenAsked) {
  auto f = part(true);
  const Feeds s = straight_feed(with(InsideCorners::slow));
  const auto slowest = [&](InsideCorners inside, bool hole) {
    auto tp = plan_sheet_toolpath(f.plan, f.parts, f.sheet, aluminium(), with(inside));
    EXPECT_TRUE(tp) << tp.error().message;
    double v = std::numeric_limits<double>::infinity();
    for (const ToolContour& c : tp->contours)
      if (c.is_hole == hole)
        for (const CutMove& m : cut_moves(*tp, c)) v = std::min(v, m.feed_mm_per_s);
    return v;
  };
  EXPECT_NEAR(slowest(InsideCorners::keep, true), s.full_mm_per_s, 1e-9);
  EXPECT_LT(slowest(InsideCorners::slow, true), 0.9 * s.full_mm_per_s);
  EXPECT_LT(slowest(InsideCorners::keep, false), 0.9 * s.full_mm_per_s);
  EXPECT_NEAR(slowest(InsideCorners::keep, false), slowest(InsideCorners::slow, false), 1e-12);
}

TEST(JetCorners, AnAllowanceThatIsNotPositiveIsRefused) {
  auto f = part(false);
  ToolpathParams p = with(InsideCorners::slow);
  p.jet_compensation.corners.error_mm = 0.0;
  auto tp = plan_sheet_toolpath(f.plan, f.parts, f.sheet, aluminium(), p);
  ASSERT_FALSE(tp);
  EXPECT_NE(tp.error().message.find("corner error allowance"), std::string::npos) << tp.error().message;
}

}  // namespace
}  // namespace lamina
