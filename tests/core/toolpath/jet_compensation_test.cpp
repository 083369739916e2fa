// Jet compensation in the toolpath (issue 20, toolpath.hpp's JetCompensation): with the jet's
// real kerf, the part's wall must run along the planned line — the top offset by the model's half
// top width, the bottom by its half bottom width, and (full) the exit aimed ahead by the
// trail-back — while off leaves every program as it was, byte for byte.
#include "toolpath_fixture.hpp"

#include <lamina/core/post.hpp>
#include <lamina/core/sheet_svg.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace lamina {
namespace {

const KerfModel kKerf{.top_width_mm = 1.2,
                      .top_width_per_ratio_mm = 0.0,
                      .taper_per_ratio = 0.1,
                      .taper_free_ratio = 0.1,
                      .trail_back_factor = 0.2,
                      .trail_back_exponent = 2.0};
constexpr double kHalfSide = 20.0, kThickness = 5.0, kKerfMm = 1.0;
const Eigen::Vector2d kCentre(100, 50);

// A 40 mm square of 5 mm plate, vertical walls, centred at kCentre on the sheet.
Fixture square() {
  return one_part(dev_test::make_layer(0, 0.0, kThickness, {dev_test::square_outline({0, 0}, kHalfSide, 0, kThickness)}), 0.0, kCentre, kKerfMm);
}

ToolpathParams with(JetCompensationMode mode) {
  ToolpathParams p;
  p.kerf_mm = kKerfMm;
  p.jet_compensation.mode = mode;
  p.jet_compensation.kerf_by_material.emplace("aluminium", kKerf);
  return p;
}

// The kerf the model gives at this sheet and the toolpath's feed on a straight edge.
KerfShape expected_kerf(const ToolpathParams& p) {
  const double feed = *cut_feed_mm_per_s(p.jet, aluminium(), p.feed, kThickness, 0.0);
  const double v_s = *separation_feed_mm_per_s(p.jet, aluminium(), p.feed, kThickness, 0.0);
  return *kerf_at(kKerf, kThickness, feed / v_s);
}

struct EdgeMove {
  Eigen::Vector3d tip, bottom, travel;
};

// Cut moves in the middle of the outer square's edges (the corners' mitres left out), once round
// (the overlap past the start left out).
std::vector<EdgeMove> edge_moves(const SheetToolpath& tp) {
  std::vector<EdgeMove> out;
  const ToolContour& outer = tp.contours.back();
  std::size_t start = outer.first_move;
  while (tp.moves[start].kind != MoveKind::lead_in || tp.moves[start].turn_piece) ++start;
  for (std::size_t i = start + 1; i < outer.end_move; ++i) {
    const ToolMove& m = tp.moves[i];
    if (m.kind != MoveKind::cut) continue;
    if (i > start + 1 && (tp.moves[i - 1].tip_mm - tp.moves[start].tip_mm).norm() < 1e-9) break;  // round once
    const Eigen::Vector2d d = (m.tip_mm.head<2>() - kCentre).cwiseAbs();
    if (std::min(d.x(), d.y()) > kHalfSide - 5.0) continue;
    const Eigen::Vector3d bottom = m.tip_mm - m.axis * (kThickness / m.axis.z());
    // Along the edge: the previous tip may be a corner's mitre, a little off the edge's line.
    const Eigen::Vector3d step = m.tip_mm - tp.moves[i - 1].tip_mm;
    const Eigen::Vector3d along = d.x() > d.y() ? Eigen::Vector3d(0, std::copysign(1.0, step.y()), 0)
                                                : Eigen::Vector3d(std::copysign(1.0, step.x()), 0, 0);
    out.push_back({m.tip_mm, bottom, along});
  }
  return out;
}

double outside_square(const Eigen::Vector3d& p) { return (p.head<2>() - kCentre).cwiseAbs().maxCoeff() - kHalfSide; }

TEST(JetCompensation, TaperPutsThePartsWallOnThePlannedLineAtBothFaces) {
  auto f = square();
  const ToolpathParams p = with(JetCompensationMode::taper);
  auto tp = plan_sheet_toolpath(f.plan, f.parts, f.sheet, aluminium(), p);
  ASSERT_TRUE(tp) << tp.error().message;
  const KerfShape k = expected_kerf(p);
  ASSERT_GT(k.top_width_mm - k.bottom_width_mm, 0.05) << "a visible taper";
  const auto moves = edge_moves(*tp);
  ASSERT_EQ(moves.size(), 4u) << "one mid-edge station per side";
  for (const EdgeMove& m : moves) {
    // The jet's centre at half its own width from the planned (vertical) wall, at each face.
    EXPECT_NEAR(outside_square(m.tip), k.top_width_mm / 2.0, 1e-9) << m.tip.transpose();
    EXPECT_NEAR(outside_square(m.bottom), k.bottom_width_mm / 2.0, 1e-9) << m.bottom.transpose();
    EXPECT_NEAR(m.bottom.z(), -kThickness, 1e-9);
  }
  EXPECT_EQ(tp->jet_tilt_limited, 0u);
}

// Full aims the exit ahead by the trail-back only where the lag would cut across the path by more
// than the corner allowance (the square's corners); along a straight edge a lag leaves the wall
// where it is, and the line stays as taper puts it (a lean there would only turn C).
TEST(JetCompensation, FullAimsTheExitAheadAtTheCornersOnly) {
  auto f = square();
  const ToolpathParams p = with(JetCompensationMode::full);
  auto full = plan_sheet_toolpath(f.plan, f.parts, f.sheet, aluminium(), p);
  auto taper = plan_sheet_toolpath(f.plan, f.parts, f.sheet, aluminium(), with(JetCompensationMode::taper));
  ASSERT_TRUE(full && taper);
  const KerfShape k = expected_kerf(p);
  ASSERT_GT(k.trail_back_mm * std::sin(std::numbers::pi / 4), p.jet_compensation.corners.error_mm) << "corners it must lean at";
  for (const EdgeMove& m : edge_moves(*full)) {
    EXPECT_NEAR((m.bottom - m.tip).dot(m.travel), 0.0, 1e-9) << "no lean along a straight edge";
    EXPECT_NEAR(outside_square(m.bottom), k.bottom_width_mm / 2.0, 1e-9);
  }
  // At the corners the bottoms differ from taper's: leaned ahead.
  ASSERT_EQ(full->moves.size(), taper->moves.size());
  int leaned = 0;
  for (std::size_t i = 0; i < full->moves.size(); ++i)
    leaned += !full->moves[i].axis.isApprox(taper->moves[i].axis, 1e-9);
  EXPECT_GE(leaned, 4) << "at least one line at each corner";
}

// The jet's lower part lags the nozzle: a ring that frees the part runs on past its start by the
// trail-back before it leaves, or the bottom of its last stretch stays uncut (a tab). Without
// compensation the trail-back is not known and the ring closes where it began, as before.
TEST(JetCompensation, AFreeingRingRunsPastItsStartByTheTrailBack) {
  auto f = square();
  auto overlap_mm = [&](JetCompensationMode mode) {
    auto tp = plan_sheet_toolpath(f.plan, f.parts, f.sheet, aluminium(), with(mode));
    EXPECT_TRUE(tp) << tp.error().message;
    const ToolContour& outer = tp->contours.back();
    EXPECT_TRUE(outer.frees && outer.closed);
    // The tips after the ring came back to its first cut's tip, to the lead-out.
    std::size_t first = outer.first_move;
    while (tp->moves[first].kind != MoveKind::lead_in || tp->moves[first].turn_piece) ++first;
    double run = 0.0;
    bool back = false;
    for (std::size_t i = first + 1; i < outer.end_move && tp->moves[i].kind == MoveKind::cut; ++i) {
      if (back) run += (tp->moves[i].tip_mm - tp->moves[i - 1].tip_mm).norm();
      back = back || (tp->moves[i].tip_mm - tp->moves[first].tip_mm).norm() < 1e-9;
    }
    return run;
  };
  const KerfShape k = expected_kerf(with(JetCompensationMode::full));
  ASSERT_GT(k.trail_back_mm, 0.05);
  EXPECT_NEAR(overlap_mm(JetCompensationMode::full), k.trail_back_mm, 1e-6);
  EXPECT_NEAR(overlap_mm(JetCompensationMode::taper), k.trail_back_mm, 1e-6);
  EXPECT_EQ(overlap_mm(JetCompensationMode::off), 0.0);
}

// A vertical wall whose two faces the taper moves by less than 0.01 mm stays vertical, at the
// mean of the two half widths: tilting the head that little would turn C at every change of
// direction and the rotary rates would slow the cut for nothing (a 1 mm sheet's taper).
TEST(JetCompensation, AVerticalWallTheTaperHardlyMovesStaysVertical) {
  constexpr double thin = 1.0;
  auto f = one_part(dev_test::make_layer(0, 0.0, thin, {dev_test::square_outline({0, 0}, kHalfSide, 0, thin)}), 0.0, kCentre, kKerfMm);
  ToolpathParams p = with(JetCompensationMode::taper);
  p.jet_compensation.kerf_by_material["aluminium"].taper_per_ratio = 0.01;
  auto tp = plan_sheet_toolpath(f.plan, f.parts, f.sheet, aluminium(), p);
  ASSERT_TRUE(tp) << tp.error().message;
  const double feed = *cut_feed_mm_per_s(p.jet, aluminium(), p.feed, thin, 0.0);
  const double v_s = *separation_feed_mm_per_s(p.jet, aluminium(), p.feed, thin, 0.0);
  KerfModel model = kKerf;
  model.taper_per_ratio = 0.01;
  const KerfShape k = *kerf_at(model, thin, feed / v_s);
  ASSERT_GT(std::abs(k.top_width_mm - k.bottom_width_mm), 1e-4) << "a taper, if a small one";
  ASSERT_LT(std::abs(k.top_width_mm - k.bottom_width_mm) / 2.0, 0.01);
  for (const ToolMove& m : tp->moves)
    if (m.kind == MoveKind::cut) EXPECT_EQ(m.axis.z(), 1.0) << m.tip_mm.transpose();
  for (const EdgeMove& m : edge_moves(*tp))
    EXPECT_NEAR(outside_square(m.tip), (k.top_width_mm + k.bottom_width_mm) / 4.0, 1e-9) << "the mean half width";
}

TEST(JetCompensation, OffKeepsTheProgramByteForByte) {
  auto f = square();
  ToolpathParams plain;
  plain.kerf_mm = kKerfMm;
  const ToolpathParams off = with(JetCompensationMode::off);
  auto a = plan_sheet_toolpath(f.plan, f.parts, f.sheet, aluminium(), plain);
  auto b = plan_sheet_toolpath(f.plan, f.parts, f.sheet, aluminium(), off);
  ASSERT_TRUE(a && b);
  HeadKinematics head;
  head.rtcp = false;
  EXPECT_EQ(post_program(*a, head, PostParams{})->text, post_program(*b, head, PostParams{})->text);
  auto c = plan_sheet_toolpath(f.plan, f.parts, f.sheet, aluminium(), with(JetCompensationMode::taper));
  ASSERT_TRUE(c);
  EXPECT_NE(post_program(*a, head, PostParams{})->text, post_program(*c, head, PostParams{})->text) << "taper changes it";
}

TEST(JetCompensation, TheTiltLimitHoldsTheLineAndIsCounted) {
  auto f = square();
  ToolpathParams p = with(JetCompensationMode::full);
  p.jet_compensation.tilt_max_rad = 0.002;  // 0.1°: less than the taper asks
  auto tp = plan_sheet_toolpath(f.plan, f.parts, f.sheet, aluminium(), p);
  ASSERT_TRUE(tp) << tp.error().message;
  EXPECT_GT(tp->jet_tilt_limited, 0u);
  std::size_t marked = 0;
  for (const ToolMove& m : tp->moves) {
    if (m.kind == MoveKind::cut) EXPECT_LE(std::acos(m.axis.z()), 0.002 + 1e-9);
    marked += m.tilt_limited;
  }
  EXPECT_GT(marked, 0u);
  // The sheet's drawing shows where: a highlighted run over those cuts, none without the limit.
  const std::string svg = sheet_svg(f.plan, f.parts, f.sheet, *tp, SheetSvgParams{});
  EXPECT_NE(svg.find("<polyline class=\"tilt-limited\""), std::string::npos);
  EXPECT_NE(svg.find("Held at the tilt limit (jet compensation)"), std::string::npos) << "and the legend says what it is";
  auto free = plan_sheet_toolpath(f.plan, f.parts, f.sheet, aluminium(), with(JetCompensationMode::full));
  ASSERT_TRUE(free);
  const std::string plain = sheet_svg(f.plan, f.parts, f.sheet, *free, SheetSvgParams{});
  EXPECT_EQ(plain.find("class=\"tilt-limited\""), std::string::npos);
  EXPECT_EQ(plain.find("Held at the tilt limit"), std::string::npos) << "no legend row for what is not there";
}

TEST(JetCompensation, AMaterialWithoutCalibrationIsNamed) {
  auto f = square();
  ToolpathParams p = with(JetCompensationMode::taper);
  p.jet_compensation.kerf_by_material.clear();
  p.jet_compensation.kerf_by_material.emplace("mild steel", kKerf);
  auto tp = plan_sheet_toolpath(f.plan, f.parts, f.sheet, aluminium(), p);
  ASSERT_FALSE(tp);
  EXPECT_NE(tp.error().message.find("no kerf calibration for 'aluminium'"), std::string::npos) << tp.error().message;
}

}  // namespace
}  // namespace lamina
