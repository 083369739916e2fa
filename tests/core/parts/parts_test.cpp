// Parts from hand-built plans: which outlines make a part, its footprint and area, dowels.
#include "hand_plans.hpp"

#include <lamina/core/parts.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>

namespace lamina {
namespace {

using dev_test::circle_outline;
using dev_test::make_layer;
using dev_test::make_outline;
using dev_test::Offsets;

TEST(Parts, OuterWithItsHolesIsOnePartAndIslandsAreNumbered) {
  BevelPlan plan;
  // Layer 3: a 40 mm square with a 10 mm square hole, and a separate 10 mm square island.
  plan.layers.push_back(make_layer(3, 10.0, 5.0,
                                   {dev_test::square_outline({0, 0}, 20, 10, 15), dev_test::square_outline({0, 0}, 5, 10, 15, true, 0),
                                    dev_test::square_outline({50, 0}, 5, 10, 15)}));
  PartParams params;
  params.kerf_mm = 1.0;
  auto parts = make_parts(plan, params);
  ASSERT_TRUE(parts) << parts.error().message;
  ASSERT_EQ(parts->size(), 2u);
  const Part& a = (*parts)[0];
  const Part& b = (*parts)[1];
  EXPECT_EQ(part_label(a), "L3-1");
  EXPECT_EQ(part_label(b), "L3-2");
  EXPECT_EQ(a.outer, 0);
  ASSERT_EQ(a.holes.size(), 1u);
  EXPECT_EQ(a.holes[0], 1);
  EXPECT_TRUE(b.holes.empty());
  EXPECT_DOUBLE_EQ(a.thickness_mm, 5.0);
  EXPECT_DOUBLE_EQ(a.z_bottom_mm, 10.0);
  // Material: 40² − 10².
  EXPECT_NEAR(a.area_mm2, 1500.0, 1e-9);
  EXPECT_NEAR(b.area_mm2, 100.0, 1e-9);
  // Footprint: the square grown by half the kerf with round corners: (40 + 1)² − (4 − π)·0.5².
  EXPECT_GT(signed_area_mm2(a.footprint_mm), 0.0);
  EXPECT_NEAR(signed_area_mm2(a.footprint_mm), 41.0 * 41.0 - (4.0 - std::numbers::pi) * 0.25, 0.01);
  // The hole's free room: the 10 mm square less half the kerf on every side.
  ASSERT_EQ(a.free_holes_mm.size(), 1u);
  EXPECT_NEAR(signed_area_mm2(a.free_holes_mm[0]), 9.0 * 9.0, 1e-6);
  EXPECT_TRUE(b.free_holes_mm.empty());
}

TEST(Parts, FootprintReachesTheWidestFaceOfATiltedCut) {
  BevelPlan plan;
  // A frustum layer: radius 20 at the bottom, 15 at the top, and a trim pass reaching 21 at the top.
  plan.layers.push_back(make_layer(0, 0.0, 10.0, {circle_outline(20.0, 64, {{20.0, 21.0}, {20.0, 15.0}}, 0.0, 10.0)}));
  auto parts = make_parts(plan, PartParams{.kerf_mm = 0.8, .dowels = {}});
  ASSERT_TRUE(parts) << parts.error().message;
  ASSERT_EQ(parts->size(), 1u);
  double r_max = 0.0;
  for (const auto& p : (*parts)[0].footprint_mm) r_max = std::max(r_max, p.norm());
  EXPECT_NEAR(r_max, 21.4, 1e-3);  // the trim pass's top ring + half the kerf
}

TEST(Parts, DowelsSitWhereEveryLayerHasMaterial) {
  BevelPlan plan;
  plan.layers.push_back(dev_test::disc_layer(0, 0.0, 5.0, 40.0, 96));
  plan.layers.push_back(dev_test::disc_layer(1, 5.0, 5.0, 25.0, 96));
  plan.layers.push_back(make_layer(2, 10.0, 5.0,
                                   {circle_outline(30.0, 96, {{30.0, 30.0}}, 10.0, 15.0),
                                    circle_outline(8.0, 48, {{8.0, 8.0}}, 10.0, 15.0, true, 0)}));
  PartParams params;
  params.dowels = {.count = 3, .diameter_mm = 4.0, .wall_mm = 2.0};
  auto parts = make_parts(plan, params);
  ASSERT_TRUE(parts) << parts.error().message;
  ASSERT_EQ(parts->size(), 3u);
  const auto& dowels = (*parts)[0].dowels_mm;
  ASSERT_EQ(dowels.size(), 3u);
  for (const Part& p : *parts) {
    ASSERT_EQ(p.dowels_mm.size(), 3u) << part_label(p);
    for (std::size_t i = 0; i < 3; ++i) EXPECT_EQ(p.dowels_mm[i], dowels[i]);
  }
  // Distance from p to the nearest edge of the regular n-gon of circumradius r (vertices at 2πj/n).
  auto to_ngon = [](const Eigen::Vector2d& p, double r, int n) {
    double best = 1e300;
    for (int j = 0; j < n; ++j) {
      const Eigen::Vector2d a(r * std::cos(2 * std::numbers::pi * j / n), r * std::sin(2 * std::numbers::pi * j / n));
      const Eigen::Vector2d b(r * std::cos(2 * std::numbers::pi * (j + 1) / n), r * std::sin(2 * std::numbers::pi * (j + 1) / n));
      const double t = std::clamp((p - a).dot(b - a) / (b - a).squaredNorm(), 0.0, 1.0);
      best = std::min(best, (a + t * (b - a) - p).norm());
    }
    return best;
  };
  for (const auto& d : dowels) {
    // Outside the 8 mm hole and inside the 25 mm disc, each by radius + wall (1 nm: Clipper's grid).
    EXPECT_GE(to_ngon(d, 8.0, 48), 4.0 - 1e-6);
    EXPECT_LT(d.norm(), 25.0);
    EXPECT_GE(to_ngon(d, 25.0, 96), 4.0 - 1e-6);
  }
  // Spread out: every pair far apart (an equilateral layout on the annulus gives > 25 mm).
  for (std::size_t i = 0; i < 3; ++i)
    for (std::size_t j = i + 1; j < 3; ++j) EXPECT_GT((dowels[i] - dowels[j]).norm(), 25.0);
}

TEST(Parts, DowelsThatDoNotFitAreAnError) {
  BevelPlan plan;
  plan.layers.push_back(dev_test::disc_layer(0, 0.0, 5.0, 6.0, 48));
  PartParams params;
  params.dowels = {.count = 2, .diameter_mm = 6.0, .wall_mm = 3.0};
  auto parts = make_parts(plan, params);
  ASSERT_FALSE(parts);
  EXPECT_EQ(parts.error().code, ErrorCode::invalid_argument);
  EXPECT_NE(parts.error().message.find("dowel"), std::string::npos) << parts.error().message;

  params.dowels = {.count = 2, .diameter_mm = 2.0, .wall_mm = 0.5};
  parts = make_parts(plan, params);
  ASSERT_TRUE(parts) << parts.error().message;  // two small ones fit in a 6 mm disc
  params.dowels = {.count = 40, .diameter_mm = 2.0, .wall_mm = 0.5};
  parts = make_parts(plan, params);
  ASSERT_FALSE(parts);
  EXPECT_NE(parts.error().message.find("only"), std::string::npos) << parts.error().message;
}

TEST(Parts, BadKerfIsNamed) {
  BevelPlan plan;
  plan.layers.push_back(dev_test::disc_layer(0, 0.0, 5.0, 6.0, 48));
  auto parts = make_parts(plan, PartParams{.kerf_mm = -1.0, .dowels = {}});
  ASSERT_FALSE(parts);
  EXPECT_NE(parts.error().message.find("kerf"), std::string::npos);
}

}  // namespace
}  // namespace lamina
