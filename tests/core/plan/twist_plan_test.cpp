// The layering's estimate is the plan's measure, and the tolerance is a 3-D distance (issue 17,
// item 4). On a twisted prism the grid estimate said 0.056 mm where the plan measured 0.159 (5 mm
// layers), 0.005 vs 0.131 (1 mm); at --tolerance 0.1 every layer failed; and every layer read
// "within tolerance" in its stations' vertical planes while the true 3-D distance was 2.11 mm:
// a per-station check cannot see a surface that turns across the layer.
#include "lamina/core/bevel.hpp"
#include "lamina/core/deviation.hpp"
#include "lamina/core/layering.hpp"
#include "lamina/core/mesh.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace lamina {
namespace {

// A 40 × 40 mm square prism 60 mm high, turned by `twist_deg` from bottom to top (rings every
// 0.5 mm, 8 points per side), closed by fans at both ends.
Mesh twisted_prism(double twist_deg) {
  constexpr int rings = 121, per_side = 8, m = 4 * per_side;
  constexpr double h = 60.0, half = 20.0;
  auto ring_point = [&](int r, int i) {
    const double z = h * r / (rings - 1);
    const double a = twist_deg * std::numbers::pi / 180.0 * z / h;
    const int side = i / per_side;
    const double f = static_cast<double>(i % per_side) / per_side;
    const double cx[4] = {-half, half, half, -half}, cy[4] = {-half, -half, half, half};
    const double x = cx[side] + (cx[(side + 1) % 4] - cx[side]) * f;
    const double y = cy[side] + (cy[(side + 1) % 4] - cy[side]) * f;
    return Eigen::Vector3f(static_cast<float>(x * std::cos(a) - y * std::sin(a)),
                           static_cast<float>(x * std::sin(a) + y * std::cos(a)), static_cast<float>(z));
  };
  TriangleSoup soup;
  auto tri = [&](Eigen::Vector3f a, Eigen::Vector3f b, Eigen::Vector3f c) {
    soup.corners.insert(soup.corners.end(), {a, b, c});
  };
  for (int r = 0; r + 1 < rings; ++r)
    for (int i = 0; i < m; ++i) {
      const int j = (i + 1) % m;
      tri(ring_point(r, i), ring_point(r, j), ring_point(r + 1, j));
      tri(ring_point(r, i), ring_point(r + 1, j), ring_point(r + 1, i));
    }
  for (int i = 0; i < m; ++i) {
    const int j = (i + 1) % m;
    tri(Eigen::Vector3f(0, 0, 0), ring_point(0, j), ring_point(0, i));
    tri(Eigen::Vector3f(0, 0, static_cast<float>(h)), ring_point(rings - 1, i), ring_point(rings - 1, j));
  }
  auto mesh = build_mesh(soup, MeshParams{});
  EXPECT_TRUE(mesh.has_value());
  return std::move(*mesh);
}

LayeringParams params(double tolerance_mm) {
  LayeringParams p;
  p.thicknesses_mm = {1.0, 2.5, 5.0, 10.0};
  p.tolerance_mm = tolerance_mm;
  return p;
}

BevelParams bevel_params(const LayeringParams& lp) {
  BevelParams b;
  b.fit = lp.fit;
  b.sub_slice_mm = lp.sub_slice_mm;
  b.tolerance_mm = lp.tolerance_mm;
  return b;
}

TEST(TwistPlan, EveryLayersEstimateIsItsMeasureAndTheStackKeepsTheTolerance) {
  const Mesh mesh = twisted_prism(90.0);
  // (0.1 gives 60 layers of 1 mm at 0.061 mm: the same check, four times the time)
  for (double tol : {0.2, 0.4}) {
    SCOPED_TRACE(::testing::Message() << "tolerance " << tol);
    const LayeringParams lp = params(tol);
    auto layering = choose_layers(mesh, lp);
    ASSERT_TRUE(layering.has_value()) << layering.error().message;
    auto plan = plan_bevels(mesh, layering->layers, bevel_params(lp));
    ASSERT_TRUE(plan.has_value());
    ASSERT_EQ(plan->layers.size(), layering->layers.size());
    // The layering hands on the plan it made of these layers: the same as planning them again.
    ASSERT_TRUE(layering->plan);
    ASSERT_EQ(layering->plan->layers.size(), plan->layers.size());
    for (std::size_t i = 0; i < plan->layers.size(); ++i) {
      EXPECT_EQ(layering->plan->layers[i].index, plan->layers[i].index);
      EXPECT_EQ(layering->plan->layers[i].z_bottom_mm, plan->layers[i].z_bottom_mm);
      EXPECT_EQ(layering->plan->layers[i].max_deviation_mm, plan->layers[i].max_deviation_mm);
      EXPECT_EQ(layering->plan->layers[i].outlines.size(), plan->layers[i].outlines.size());
    }
    for (std::size_t i = 0; i < plan->layers.size(); ++i) {
      const double estimate = layering->layers[i].estimated_deviation_mm;
      const double measure = plan->layers[i].max_deviation_mm;
      EXPECT_NEAR(estimate, measure, 0.2 * std::max(measure, 0.01)) << "layer " << i;
      EXPECT_TRUE(plan->layers[i].within_tolerance) << "layer " << i << ": " << measure;
    }
    // The stack as a whole, measured independently (sampled Hausdorff over the stack's mesh).
    auto dev = measure_deviation(mesh, *plan, DeviationParams{});
    ASSERT_TRUE(dev.has_value());
    EXPECT_LE(dev->max_mm, tol + 0.01) << "a layer within tolerance must be so in 3-D";
  }
}

TEST(TwistPlan, ALayersMeasureIsTheThreeDimensionalDistanceItsStationsCannotSee) {
  // Five 10 mm layers of a prism turned 90°: each layer's corners slide 16 mm along the outline.
  const Mesh mesh = twisted_prism(90.0);
  std::vector<LayerSpan> layers;
  for (int i = 0; i < 6; ++i) layers.push_back({10.0 * i, 10.0, 0.0, true});
  const LayeringParams lp = params(0.2);
  auto plan = plan_bevels(mesh, layers, bevel_params(lp));
  ASSERT_TRUE(plan.has_value());
  auto dev = measure_deviation(mesh, *plan, DeviationParams{});
  ASSERT_TRUE(dev.has_value());
  double worst = 0.0;
  for (const LayerPlan& l : plan->layers) {
    EXPECT_GE(l.surface_distance_mm, 0.0) << "measured";
    EXPECT_EQ(l.max_deviation_mm, l.surface_distance_mm);
    worst = std::max(worst, l.max_deviation_mm);
  }
  // The layers' own measure finds what the independent whole-stack distance finds (its samples
  // include the exposed faces, which a layer alone does not know: within 10 %).
  EXPECT_NEAR(worst, dev->max_mm, 0.1 * dev->max_mm);
}

}  // namespace
}  // namespace lamina
