// Straight sloped walls within the machine's tilt limit are cut exactly by one sloped jet line
// per station, whatever the sheet thickness: the achievable deviation is zero and the optimal
// layering takes the thickest sheets, where the paper's area criterion (blind to bevelling)
// keeps splitting.
#include "layering_checks.hpp"
#include "mesh_soups.hpp"

#include <lamina/core/layering.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace lamina {
namespace {

using layering_test::build;
using layering_test::expect_well_formed;
using layering_test::stock_params;

// A cone of base radius r and height h (apex up), `n` sides, base on z = 0.
TriangleSoup cone(double r, double h, int n) {
  TriangleSoup s;
  s.format = "test";
  const Eigen::Vector3f apex(0, 0, static_cast<float>(h)), centre(0, 0, 0);
  auto at = [&](int j) {
    const double a = 2 * std::numbers::pi * (j % n) / n;
    return Eigen::Vector3f(static_cast<float>(r * std::cos(a)), static_cast<float>(r * std::sin(a)), 0.0f);
  };
  for (int j = 0; j < n; ++j) {
    mesh_test::add_tri(s, at(j), at(j + 1), apex);
    mesh_test::add_tri(s, centre, at(j + 1), at(j));
  }
  return s;
}

TEST(LayeringSloped, DoubleConeWithinTheTiltLimitTakesTheThickestSheets) {
  // Two 45° cones base to base (a UV sphere with two bands): 40 mm = 4 × 10 mm, each exact.
  const Mesh mesh = build(mesh_test::uv_sphere(20, 64, 2));
  const auto p = stock_params();  // tilt limit 60°, tolerance 0.1 mm
  auto r = choose_layers(mesh, p);
  ASSERT_TRUE(r.has_value()) << r.error().message;
  expect_well_formed(*r, p);
  ASSERT_EQ(r->layers.size(), 4u);
  for (const auto& l : r->layers) {
    EXPECT_EQ(l.thickness_mm, 10.0);
    // The plan's 3-D measure (issue 17, item 4) reads sub-slices 1 µm inside the faces: exact
    // ruled cuts read as about that much.
    EXPECT_LT(l.estimated_deviation_mm, 2e-3) << "z " << l.z_bottom_mm;
  }

  auto g = choose_layers(mesh, stock_params(LayeringMethod::greedy));
  ASSERT_TRUE(g.has_value());
  expect_well_formed(*g, stock_params(LayeringMethod::greedy));
  EXPECT_GT(g->layers.size(), 3 * r->layers.size()) << "the section area changes fast on a cone";
}

TEST(LayeringSloped, ConeFlatterThanTheTiltLimitNeedsThinnerSheets) {
  // A 30 mm cone 20 mm tall: its wall leans 56° from vertical, inside a 60° limit (exact at any
  // thickness) but outside a 45° one, where the jet must stay steeper than the wall and leaves
  // a strip whose width grows with the sheet thickness (about half of it here).
  const Mesh mesh = build(cone(30, 20, 96));
  auto p = stock_params();
  p.tolerance_mm = 0.6;
  auto wide = choose_layers(mesh, p);
  ASSERT_TRUE(wide.has_value());
  expect_well_formed(*wide, p);
  EXPECT_EQ(wide->layers.size(), 2u);
  EXPECT_TRUE(wide->shortfalls.empty());
  for (const auto& l : wide->layers) EXPECT_LT(l.estimated_deviation_mm, 1e-2);

  auto g = choose_layers(mesh, stock_params(LayeringMethod::greedy));
  ASSERT_TRUE(g.has_value());
  EXPECT_GT(g->layers.size(), wide->layers.size()) << "the paper's rule does not see the bevel";

  p.fit.tilt_max_rad = std::numbers::pi / 4;
  auto narrow = choose_layers(mesh, p);
  ASSERT_TRUE(narrow.has_value());
  expect_well_formed(*narrow, p);
  EXPECT_TRUE(narrow->shortfalls.empty());
  // Along the wall only 1 mm sheets keep the strip within 0.6 mm. The last layer holds the
  // apex, where the wall ends inside it: a thicker sheet may stay within there (its plan
  // measures 0.55 mm for 2.5 mm), and the stack is then a layer shorter.
  ASSERT_GE(narrow->layers.size(), 19u) << "only 1 mm sheets stay within 0.6 mm at a 45° limit";
  double previous = 0.0;
  for (std::size_t i = 0; i < narrow->layers.size(); ++i) {
    const LayerSpan& l = narrow->layers[i];
    if (i + 1 < narrow->layers.size()) EXPECT_EQ(l.thickness_mm, 1.0) << "layer " << i;
    EXPECT_TRUE(l.within_tolerance) << "layer " << i;
    EXPECT_GT(l.estimated_deviation_mm, 0.2) << "the strip the limit leaves is seen";
    previous = std::max(previous, l.estimated_deviation_mm);
  }
  EXPECT_LE(previous, 0.6);
}

}  // namespace
}  // namespace lamina
