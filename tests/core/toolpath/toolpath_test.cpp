// Sheet toolpaths from hand-built plans: order, leads, kerf in 5 axes, trim runs, microjoints,
// dowels, feeds and time.
#include "hand_plans.hpp"
#include "toolpath_fixture.hpp"

#include <lamina/core/toolpath.hpp>

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <cmath>
#include <numbers>

namespace lamina {
namespace {

using dev_test::circle_outline;
using dev_test::make_layer;
using dev_test::make_outline;
using dev_test::Offsets;

ToolpathParams params_with_kerf(double kerf) {
  ToolpathParams p;
  p.kerf_mm = kerf;
  return p;
}

// The tips of a contour's cut moves (and the lead-in's end), in order.
std::vector<Eigen::Vector3d> cut_tips(const SheetToolpath& tp, const ToolContour& c) {
  std::vector<Eigen::Vector3d> out;
  for (std::size_t i = c.first_move; i < c.end_move; ++i)
    if ((tp.moves[i].kind == MoveKind::lead_in || tp.moves[i].kind == MoveKind::cut) && !tp.moves[i].turn_piece)
      out.push_back(tp.moves[i].tip_mm);
  return out;
}

double signed_area(const std::vector<Eigen::Vector3d>& ring) {
  double a = 0.0;
  for (std::size_t i = 0; i < ring.size(); ++i) {
    const auto& p = ring[i];
    const auto& q = ring[(i + 1) % ring.size()];
    a += p.x() * q.y() - q.x() * p.y();
  }
  return 0.5 * a;
}

// Distance from p to the boundary of the axis-aligned square |x − c| ≤ half (outside or inside).
double to_square(const Eigen::Vector2d& p, const Eigen::Vector2d& c, double half) {
  const Eigen::Vector2d d = (p - c).cwiseAbs() - Eigen::Vector2d(half, half);
  const double outside = d.cwiseMax(0.0).norm();
  return outside > 0.0 ? outside : -d.maxCoeff();
}

TEST(Toolpath, HolesFirstThenTheOuterWithKerfAndLeadsInTheScrap) {
  const double kerf = 1.0, h = 0.5;
  auto f = one_part(make_layer(0, 0.0, 5.0, {dev_test::square_outline({0, 0}, 20, 0, 5), dev_test::square_outline({0, 0}, 5, 0, 5, true, 0)}),
                    std::numbers::pi / 2, {100, 50}, kerf);
  auto tp = plan_sheet_toolpath(f.plan, f.parts, f.sheet, aluminium(), params_with_kerf(kerf));
  ASSERT_TRUE(tp) << tp.error().message;
  ASSERT_EQ(tp->contours.size(), 2u);
  const ToolContour& hole = tp->contours[0];
  const ToolContour& outer = tp->contours[1];
  EXPECT_TRUE(hole.is_hole);
  EXPECT_FALSE(outer.is_hole);
  EXPECT_TRUE(hole.frees && hole.closed && outer.frees && outer.closed);
  const Eigen::Vector2d c(100, 50);  // the layer's origin lands here; squares are symmetric under 90°

  // Tips on the top face, at half the kerf from the square — outside for the outer, inside the hole.
  for (const auto& p : cut_tips(*tp, outer)) {
    EXPECT_NEAR(p.z(), 0.0, 1e-12);
    const Eigen::Vector2d d = (p.head<2>() - c).cwiseAbs();
    // Along the edges exactly h out; at the mitred corners h out from both edges.
    EXPECT_NEAR(std::max(d.x(), d.y()), 20.0 + h, 1e-9) << p.transpose();
  }
  for (const auto& p : cut_tips(*tp, hole)) {
    const Eigen::Vector2d d = (p.head<2>() - c).cwiseAbs();
    EXPECT_NEAR(std::max(d.x(), d.y()), 5.0 - h, 1e-9) << p.transpose();
  }
  // The jet's good side: outer clockwise, hole counter-clockwise.
  EXPECT_LT(signed_area(cut_tips(*tp, outer)), 0.0);
  EXPECT_GT(signed_area(cut_tips(*tp, hole)), 0.0);
  // Pierces in the scrap: outside the outer's kerf, inside the hole's.
  EXPECT_GT(to_square(outer.pierce_mm, c, 20.0), h);
  EXPECT_LT((outer.pierce_mm - c).cwiseAbs().maxCoeff(), 20.0 + 3.0 + h + 1e-9);
  EXPECT_LT((hole.pierce_mm - c).cwiseAbs().maxCoeff(), 5.0 - h);

  // The move sequence of a contour and the jet's state along it.
  for (const ToolContour& k : tp->contours) {
    const auto& m = tp->moves;
    ASSERT_GE(k.end_move - k.first_move, 6u);
    EXPECT_EQ(m[k.first_move].kind, MoveKind::rapid);
    EXPECT_NEAR(m[k.first_move].tip_mm.z(), ToolpathParams{}.safe_z_mm, 1e-12);
    EXPECT_EQ(m[k.first_move + 1].kind, MoveKind::rapid);
    EXPECT_EQ(m[k.first_move + 2].kind, MoveKind::pierce);
    EXPECT_TRUE(m[k.first_move + 2].jet_on);
    EXPECT_DOUBLE_EQ(m[k.first_move + 2].dwell_s, ToolpathParams{}.pierce_dwell_s);
    EXPECT_EQ(m[k.first_move + 3].kind, MoveKind::lead_in);
    EXPECT_EQ(m[k.end_move - 2].kind, MoveKind::lead_out);
    EXPECT_EQ(m[k.end_move - 1].kind, MoveKind::rapid);
    for (std::size_t i = k.first_move; i < k.end_move; ++i) {
      EXPECT_EQ(m[i].contour, static_cast<int>(&k - tp->contours.data()));
      EXPECT_EQ(m[i].jet_on, m[i].kind != MoveKind::rapid);
    }
  }
  // Cut time adds up, and the sheet starts and ends at the park position at safe height.
  double total = 0.0;
  for (const auto& m : tp->moves) total += m.duration_s;
  EXPECT_NEAR(tp->time.total_s, total, 1e-9);
  EXPECT_EQ(tp->time.pierces, 2);
  EXPECT_NEAR(tp->time.pierce_s, 2 * ToolpathParams{}.pierce_dwell_s, 1e-12);
  EXPECT_EQ(tp->moves.back().kind, MoveKind::rapid);
  EXPECT_NEAR(tp->moves.back().tip_mm.z(), ToolpathParams{}.safe_z_mm, 1e-12);
}

// The distance between two parallel 3-D lines through a and b along unit u.
double line_distance(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& u) {
  const Eigen::Vector3d d = b - a;
  return (d - d.dot(u) * u).norm();
}

TEST(Toolpath, KerfOffsetsTheRuledSurfaceAlongItsNormalNotTheTopContour) {
  // A cone layer: radius 20 at the bottom, 17 at the top of a 6 mm sheet (tilt atan(0.5) = 26.6°).
  const double kerf = 1.0, h = 0.5;
  auto f = one_part(make_layer(0, 0.0, 6.0, {circle_outline(20.0, 180, {{20.0, 17.0}}, 0.0, 6.0)}), 0.0, {200, 200}, kerf);
  auto tp = plan_sheet_toolpath(f.plan, f.parts, f.sheet, aluminium(), params_with_kerf(kerf));
  ASSERT_TRUE(tp) << tp.error().message;
  ASSERT_EQ(tp->contours.size(), 1u);
  const Eigen::Vector3d c(200, 200, 0);
  const double tilt = std::atan(0.5);
  int checked = 0;
  for (std::size_t i = tp->contours[0].first_move; i < tp->contours[0].end_move; ++i) {
    const ToolMove& m = tp->moves[i];
    if (m.kind != MoveKind::cut) continue;
    // The uncompensated line through the same meridian: top at r = 17 (z = 0), bottom at r = 20.
    const Eigen::Vector3d radial = Eigen::Vector3d(m.tip_mm.x() - c.x(), m.tip_mm.y() - c.y(), 0).normalized();
    const Eigen::Vector3d top = c + 17.0 * radial, bottom = c + 20.0 * radial - Eigen::Vector3d(0, 0, 6.0);
    const Eigen::Vector3d u = (top - bottom).normalized();
    EXPECT_NEAR(m.axis.dot(u), 1.0, 1e-9);
    EXPECT_NEAR(line_distance(top, m.tip_mm, u), h, 2e-3);  // 180-gon: the facets' normals differ by 1°
    // The tip moved out by h / cos(tilt) on the top face, more than a 2-D offset of the top ring would.
    EXPECT_NEAR((m.tip_mm - c).norm(), 17.0 + h / std::cos(tilt), 2e-3);
    ++checked;
  }
  EXPECT_GT(checked, 150);
}

TEST(Toolpath, VerticalPiercesClearThePartOnBothFaces) {
  // A dome-like wall: radius 20 at the bottom, 14 at the top of a 6 mm sheet. A pierce 3 mm off the
  // top contour would land on the part's bottom edge; it must land 3 mm beyond the bottom one.
  const double kerf = 0.8;
  auto f = one_part(make_layer(0, 0.0, 6.0, {circle_outline(20.0, 120, {{20.0, 14.0}}, 0.0, 6.0)}), 0.0, {100, 100}, kerf);
  auto tp = plan_sheet_toolpath(f.plan, f.parts, f.sheet, aluminium(), params_with_kerf(kerf));
  ASSERT_TRUE(tp) << tp.error().message;
  ASSERT_EQ(tp->contours.size(), 1u);
  const double r = (tp->contours[0].pierce_mm - Eigen::Vector2d(100, 100)).norm();
  EXPECT_GT(r, 20.0 + 0.5 * kerf + 3.0 - 0.05);
  EXPECT_LT(r, 20.0 + 0.5 * kerf + 3.0 + 0.5);
}

TEST(Toolpath, FeedsFollowTheModelAtEachLinesTilt) {
  const Material al = aluminium();
  const ToolpathParams p = params_with_kerf(0.0);
  auto cone = one_part(make_layer(0, 0.0, 6.0, {circle_outline(20.0, 120, {{20.0, 14.0}}, 0.0, 6.0)}), 0.0, {100, 100}, 0.0);
  auto cylinder = one_part(make_layer(0, 0.0, 6.0, {circle_outline(20.0, 120, {{20.0, 20.0}}, 0.0, 6.0)}), 0.0, {100, 100}, 0.0);
  auto a = plan_sheet_toolpath(cone.plan, cone.parts, cone.sheet, al, p);
  auto b = plan_sheet_toolpath(cylinder.plan, cylinder.parts, cylinder.sheet, al, p);
  ASSERT_TRUE(a && b);
  const double tilt = std::atan(1.0);
  const double want_tilted = *cut_feed_mm_per_s(p.jet, al, p.feed, 6.0, tilt);
  const double want_vertical = *cut_feed_mm_per_s(p.jet, al, p.feed, 6.0, 0.0);
  EXPECT_LT(want_tilted, want_vertical);  // a longer path through the sheet: slower
  for (const auto& [tp, want] : {std::pair{&*a, want_tilted}, std::pair{&*b, want_vertical}})
    for (const ToolMove& m : tp->moves)
      if (m.kind == MoveKind::cut) {
        EXPECT_NEAR(m.feed_mm_per_s, want, 1e-9 * want);
      }
}

TEST(Toolpath, SharpCornersAreEnteredSlower) {
  auto f = one_part(make_layer(0, 0.0, 5.0, {dev_test::square_outline({0, 0}, 20, 0, 5)}), 0.0, {100, 100}, 0.0);
  ToolpathParams p = params_with_kerf(0.0);
  auto tp = plan_sheet_toolpath(f.plan, f.parts, f.sheet, aluminium(), p);
  ASSERT_TRUE(tp);
  const double full = *cut_feed_mm_per_s(p.jet, aluminium(), p.feed, 5.0, 0.0);
  int slow = 0, fast = 0;
  for (const ToolMove& m : tp->moves) {
    if (m.kind != MoveKind::cut) continue;
    // Every cut move touches a corner of the square (stations at corners and mid-edges).
    const Eigen::Vector2d d = (m.tip_mm.head<2>() - Eigen::Vector2d(100, 100)).cwiseAbs();
    const bool at_corner = std::abs(d.x() - 20) < 1e-9 && std::abs(d.y() - 20) < 1e-9;
    EXPECT_NEAR(m.feed_mm_per_s, std::max(p.corner_min_fraction, std::cos(std::numbers::pi / 4)) * full, 1e-9 * full);
    slow += at_corner;
    fast += !at_corner;
  }
  EXPECT_EQ(slow, 4);
  EXPECT_EQ(fast, 4);
}

// An outline whose convex half (stations with y > 0) has three tangent cuts and whose other half one.
LayerOutline half_convex_disc(bool convex_everywhere) {
  const auto disc = dev_test::circle_stations(20.0, 72);
  return make_outline(
      disc.first, disc.second,
      3,
      [convex_everywhere](int pass, std::size_t s) {
        const bool convex = convex_everywhere || (s > 0 && s < 36);
        if (!convex) return Offsets{0.0, -1.0};
        const Offsets tangents[3] = {{-2.0, 0.5}, {0.2, 0.2}, {0.5, -2.0}};
        return tangents[pass];
      },
      0.0, 8.0);
}

TEST(Toolpath, TrimRunsComeBeforeTheFreeingPassAndStartOnItsSurface) {
  auto f = one_part(make_layer(0, 0.0, 8.0, {half_convex_disc(false)}), 0.0, {100, 100}, 0.0);
  auto tp = plan_sheet_toolpath(f.plan, f.parts, f.sheet, aluminium(), params_with_kerf(0.0));
  ASSERT_TRUE(tp) << tp.error().message;
  ASSERT_EQ(tp->contours.size(), 3u);  // two trim runs (passes 0 and 1), then the closed last pass
  for (int k = 0; k < 2; ++k) {
    const ToolContour& c = tp->contours[static_cast<std::size_t>(k)];
    EXPECT_EQ(c.pass, k);
    EXPECT_FALSE(c.frees);
    EXPECT_FALSE(c.closed);
    // Starts and ends on lines shared with the last pass (the non-convex half: top at r = 19).
    const auto tips = cut_tips(*tp, c);
    EXPECT_NEAR((tips.front().head<2>() - Eigen::Vector2d(100, 100)).norm(), 19.0, 1e-9);
    EXPECT_NEAR((tips.back().head<2>() - Eigen::Vector2d(100, 100)).norm(), 19.0, 1e-9);
    // 35 convex stations + one shared at each end.
    EXPECT_EQ(tips.size(), 37u);
  }
  EXPECT_EQ(tp->contours[2].pass, 2);
  EXPECT_TRUE(tp->contours[2].frees && tp->contours[2].closed);
}

TEST(Toolpath, TrimRunsSplitByShortSharedStretchesAreCutAsOne) {
  // Every other station convex (as on a faceted surface): 36 runs of one line per trim pass
  // would cost 36 pierces; the 1.7 mm shared stretches between them are cut through instead.
  const auto disc = dev_test::circle_stations(20.0, 72);
  LayerOutline o = make_outline(
      disc.first, disc.second,
      3,
      [](int pass, std::size_t s) {
        if (s % 2) return Offsets{0.0, -1.0};
        const Offsets tangents[3] = {{-2.0, 0.5}, {0.2, 0.2}, {0.5, -2.0}};
        return tangents[pass];
      },
      0.0, 8.0);
  auto f = one_part(make_layer(0, 0.0, 8.0, {o}), 0.0, {100, 100}, 0.8);
  ToolpathParams p = params_with_kerf(0.8);
  auto tp = plan_sheet_toolpath(f.plan, f.parts, f.sheet, aluminium(), p);
  ASSERT_TRUE(tp) << tp.error().message;
  ASSERT_EQ(tp->contours.size(), 3u);  // one bridged run per trim pass, then the freeing pass
  EXPECT_FALSE(tp->contours[0].closed);
  EXPECT_FALSE(tp->contours[1].closed);
  EXPECT_TRUE(tp->contours[2].closed && tp->contours[2].frees);
  // With a free pierce (no dwell, no leads) the stretches are not worth crossing: one run each.
  p.pierce_dwell_s = 0.0;
  p.lead_in_mm = p.lead_out_mm = 0.0;
  tp = plan_sheet_toolpath(f.plan, f.parts, f.sheet, aluminium(), p);
  ASSERT_TRUE(tp) << tp.error().message;
  EXPECT_EQ(tp->contours.size(), 2u * 36u + 1u);
}

TEST(Toolpath, ATrimPassThatWouldFreeThePartLeavesABridge) {
  auto f = one_part(make_layer(0, 0.0, 8.0, {half_convex_disc(true)}), 0.0, {100, 100}, 0.8);
  ToolpathParams p = params_with_kerf(0.8);
  auto tp = plan_sheet_toolpath(f.plan, f.parts, f.sheet, aluminium(), p);
  ASSERT_TRUE(tp) << tp.error().message;
  ASSERT_EQ(tp->contours.size(), 3u);
  for (int k = 0; k < 2; ++k) {
    const auto tips = cut_tips(*tp, tp->contours[static_cast<std::size_t>(k)]);
    EXPECT_FALSE(tp->contours[static_cast<std::size_t>(k)].closed);
    // The gap between the run's end and its start: the bridge's width plus the kerf.
    EXPECT_NEAR((tips.back() - tips.front()).norm(), p.microjoint_width_mm + p.kerf_mm, 0.01);
  }
  EXPECT_TRUE(tp->contours[2].closed);
}

TEST(Toolpath, MicrojointsSplitTheFreeingPassAndEveryTrimPassAtTheSamePlaces) {
  auto f = one_part(make_layer(0, 0.0, 8.0, {half_convex_disc(true)}), 0.0, {100, 100}, 0.8);
  ToolpathParams p = params_with_kerf(0.8);
  p.microjoints = 4;
  p.microjoint_width_mm = 1.0;
  auto tp = plan_sheet_toolpath(f.plan, f.parts, f.sheet, aluminium(), p);
  ASSERT_TRUE(tp) << tp.error().message;
  ASSERT_EQ(tp->contours.size(), 12u);  // 3 passes × 4 runs
  ASSERT_EQ(tp->microjoints.size(), 4u);
  for (const Microjoint& j : tp->microjoints) EXPECT_NEAR((j.to_mm - j.from_mm).norm(), 1.0, 0.01);
  int freeing = 0;
  for (const ToolContour& c : tp->contours) {
    EXPECT_FALSE(c.closed);
    freeing += c.frees;
  }
  EXPECT_EQ(freeing, 4);
  EXPECT_EQ(tp->time.pierces, 12);
  // No cut of any pass runs through a microjoint's uncut material.
  for (const Microjoint& j : tp->microjoints) {
    const Eigen::Vector2d mid = 0.5 * (j.from_mm + j.to_mm);
    for (const ToolMove& m : tp->moves)
      if (m.kind == MoveKind::cut) {
        EXPECT_GT((m.tip_mm.head<2>() - mid).norm(), 0.45) << "through a microjoint";
      }
  }
}

TEST(Toolpath, SmallHolesGetAShortLeadAndDowelsAreCutVertical) {
  auto f = one_part(make_layer(0, 0.0, 5.0, {circle_outline(30.0, 96, {{30.0, 30.0}}, 0.0, 5.0),
                                             circle_outline(2.0, 32, {{2.0, 2.0}}, 0.0, 5.0, true, 0, {10, 0})}),
                    0.0, {100, 100}, 0.8);
  f.parts[0].dowels_mm = {{-15.0, 0.0}};
  ToolpathParams p = params_with_kerf(0.8);
  p.dowel_diameter_mm = 5.0;
  auto tp = plan_sheet_toolpath(f.plan, f.parts, f.sheet, aluminium(), p);
  ASSERT_TRUE(tp) << tp.error().message;
  ASSERT_EQ(tp->contours.size(), 3u);
  const ToolContour& dowel = tp->contours[0];
  const ToolContour& hole = tp->contours[1];
  EXPECT_EQ(dowel.outline, -1);
  EXPECT_EQ(hole.outline, 1);
  for (const auto& q : cut_tips(*tp, dowel)) EXPECT_NEAR((q.head<2>() - Eigen::Vector2d(85, 100)).norm(), 2.5 - 0.4, 1e-9);
  for (std::size_t i = dowel.first_move; i < dowel.end_move; ++i)
    if (tp->moves[i].kind == MoveKind::cut) {
      EXPECT_NEAR(tp->moves[i].axis.z(), 1.0, 1e-12);
    }
  // The Ø4 hole's pierce: inside the jet path (radius 1.6), not 3 mm out into the part.
  EXPECT_LT((hole.pierce_mm - Eigen::Vector2d(110, 100)).norm(), 1.6);
}

TEST(Toolpath, APartNestedInAHoleIsCutBeforeItsHost) {
  // Layer 0: a ring (Ø100 with a Ø80 hole); layer 1: a Ø30 disc, nested in the ring's hole.
  Fixture f;
  f.plan.layers.push_back(make_layer(0, 0.0, 5.0, {circle_outline(50.0, 96, {{50.0, 50.0}}, 0.0, 5.0),
                                                   circle_outline(40.0, 96, {{40.0, 40.0}}, 0.0, 5.0, true, 0)}));
  f.plan.layers.push_back(make_layer(1, 5.0, 5.0, {circle_outline(15.0, 48, {{15.0, 15.0}}, 5.0, 10.0)}));
  f.parts = *make_parts(f.plan, PartParams{});
  f.sheet.index = 1;
  f.sheet.thickness_mm = 5.0;
  f.sheet.width_mm = f.sheet.length_mm = 300;
  // Listed host first, and the host's pierce nearer the park position: only Placement::host puts
  // the disc first.
  f.sheet.placements.push_back({0, 0.0, {100, 100}, -1});
  f.sheet.placements.push_back({1, 0.0, {110, 100}, 0});
  auto tp = plan_sheet_toolpath(f.plan, f.parts, f.sheet, aluminium(), ToolpathParams{});
  ASSERT_TRUE(tp) << tp.error().message;
  ASSERT_EQ(tp->contours.size(), 3u);
  EXPECT_EQ(tp->contours[0].placement, 1);  // the disc, whole
  EXPECT_EQ(tp->contours[1].placement, 0);  // then the ring's hole (freeing the slug the disc sat on)
  EXPECT_TRUE(tp->contours[1].is_hole);
  EXPECT_EQ(tp->contours[2].placement, 0);

  f.sheet.placements[0].host = 1;  // each the other's host: no order can work
  tp = plan_sheet_toolpath(f.plan, f.parts, f.sheet, aluminium(), ToolpathParams{});
  ASSERT_FALSE(tp);
  EXPECT_NE(tp.error().message.find("cycle"), std::string::npos) << tp.error().message;
}

TEST(Toolpath, BadInputsAreNamed) {
  auto f = one_part(dev_test::disc_layer(0, 0.0, 5.0, 20.0, 48), 0.0, {100, 100});
  ToolpathParams p;
  p.safe_z_mm = 0.0;
  auto tp = plan_sheet_toolpath(f.plan, f.parts, f.sheet, aluminium(), p);
  ASSERT_FALSE(tp);
  EXPECT_NE(tp.error().message.find("safe height"), std::string::npos);
  f.sheet.thickness_mm = 6.0;
  tp = plan_sheet_toolpath(f.plan, f.parts, f.sheet, aluminium(), ToolpathParams{});
  ASSERT_FALSE(tp);
  EXPECT_NE(tp.error().message.find("L0-1"), std::string::npos) << tp.error().message;
  f.sheet.thickness_mm = 5.0;
  p = ToolpathParams{};
  p.microjoints = 30;
  p.microjoint_width_mm = 5.0;
  tp = plan_sheet_toolpath(f.plan, f.parts, f.sheet, aluminium(), p);
  ASSERT_FALSE(tp);
  EXPECT_NE(tp.error().message.find("microjoint"), std::string::npos) << tp.error().message;
}

}  // namespace
}  // namespace lamina
