// A sphere standing on its pole: near the poles the surface is flatter than the machine can tilt
// (60°), so only thin sheets keep the achievable deviation small; around the equator the wall is
// nearly vertical and thick sheets bevel well. The target: at most 25 layers.
#include "layering_checks.hpp"
#include "mesh_soups.hpp"

#include <lamina/core/layering.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <numbers>

namespace lamina {
namespace {

using layering_test::build;
using layering_test::expect_well_formed;
using layering_test::max_estimate;
using layering_test::stock_params;

constexpr double kR = 50.0;

const Mesh& sphere() {
  static const Mesh m = build(mesh_test::uv_sphere(kR, 128, 64));
  return m;
}

LayeringParams sphere_params(LayeringMethod method, double tolerance = 0.3) {
  auto p = stock_params(method);
  p.fit.tilt_max_rad = 60.0 * std::numbers::pi / 180.0;
  p.tolerance_mm = tolerance;
  return p;
}

const LayerSpan& layer_at(const Layering& l, double z) {
  for (const auto& s : l.layers)
    if (s.z_bottom_mm <= z && z < s.z_top_mm()) return s;
  return l.layers.back();
}

TEST(LayeringSphere, OptimalUsesThinSheetsAtThePolesAndThickOnesAroundTheEquator) {
  const auto p = sphere_params(LayeringMethod::optimal);
  auto r = choose_layers(sphere(), p);
  ASSERT_TRUE(r.has_value()) << r.error().message;
  expect_well_formed(*r, p);
  EXPECT_NEAR(r->model_height_mm, 2 * kR, 1e-4);
  EXPECT_LE(r->layers.size(), 25u) << "the issue's target";
  EXPECT_EQ(r->layers.front().thickness_mm, 1.0);
  EXPECT_EQ(r->layers.back().thickness_mm, 1.0);
  EXPECT_EQ(layer_at(*r, kR).thickness_mm, 10.0);
  // Sheets get thinner towards the poles: the average within 20 mm of the equator is well above
  // the average within 10 mm of a pole.
  double mid = 0, mid_n = 0, pole = 0, pole_n = 0;
  for (const auto& l : r->layers) {
    const double c = 0.5 * (l.z_bottom_mm + l.z_top_mm());
    if (std::abs(c - kR) < 20) mid += l.thickness_mm, ++mid_n;
    if (c < 10 || c > 2 * kR - 10) pole += l.thickness_mm, ++pole_n;
  }
  ASSERT_GT(mid_n, 0);
  ASSERT_GT(pole_n, 0);
  EXPECT_GT(mid / mid_n, 2.0 * (pole / pole_n));
  // Where a pole is flatter than the tilt limit no sheet meets 0.3 mm: that is reported, at both
  // ends, not hidden.
  ASSERT_FALSE(r->shortfalls.empty());
  EXPECT_LT(r->shortfalls.front().z_from_mm, 1e-9);
  EXPECT_GT(r->shortfalls.back().z_to_mm, 2 * kR - 1e-6);
  for (const auto& s : r->shortfalls) EXPECT_LT(std::min(s.z_from_mm, 2 * kR - s.z_to_mm), 15.0);
}

TEST(LayeringSphere, LooseToleranceNeedsOnlyTheThickestSheet) {
  // With a tolerance above every estimate every sheet is allowed: 100 mm = 10 × 10 mm.
  const auto p = sphere_params(LayeringMethod::optimal, 50.0);
  auto r = choose_layers(sphere(), p);
  ASSERT_TRUE(r.has_value());
  expect_well_formed(*r, p);
  EXPECT_EQ(r->layers.size(), 10u);
  EXPECT_TRUE(r->shortfalls.empty());
}

TEST(LayeringSphere, GreedyNeverBeatsOptimalAtTheSameTolerance) {
  const auto pg = sphere_params(LayeringMethod::greedy);
  auto gr = choose_layers(sphere(), pg);
  ASSERT_TRUE(gr.has_value());
  expect_well_formed(*gr, pg);
  // The greedy layers meet the tolerance their own worst estimate sets; at that tolerance the
  // optimal layering may use the greedy one, so it cannot need more layers.
  const double tol = max_estimate(*gr);
  const auto po = sphere_params(LayeringMethod::optimal, tol);
  auto opt = choose_layers(sphere(), po);
  ASSERT_TRUE(opt.has_value());
  expect_well_formed(*opt, po);
  EXPECT_LE(opt->layers.size(), gr->layers.size());
  EXPECT_LE(max_estimate(*opt), tol);
  EXPECT_TRUE(opt->shortfalls.empty());

  // And at the 0.3 mm the optimal layering is far leaner than the paper's rule.
  auto opt03 = choose_layers(sphere(), sphere_params(LayeringMethod::optimal));
  ASSERT_TRUE(opt03.has_value());
  EXPECT_LT(opt03->layers.size(), gr->layers.size());
}

TEST(LayeringSphere, GreedyUsesThickSheetsOnlyWhereTheSectionBarelyChanges) {
  const auto p = sphere_params(LayeringMethod::greedy);
  auto r = choose_layers(sphere(), p);
  ASSERT_TRUE(r.has_value());
  expect_well_formed(*r, p);
  EXPECT_EQ(r->layers.front().thickness_mm, 1.0);
  EXPECT_GE(layer_at(*r, kR).thickness_mm, 5.0);
  for (const auto& l : r->layers) EXPECT_TRUE(std::isfinite(l.estimated_deviation_mm));
}

TEST(LayeringSphere, ParallelAndSerialGiveIdenticalLayerings) {
  for (auto method : {LayeringMethod::optimal, LayeringMethod::greedy}) {
    SCOPED_TRACE(layering_method_name(method));
    auto p = sphere_params(method);
    p.bond_mm = 0.1;
    p.parallel = true;
    auto a = choose_layers(sphere(), p);
    p.parallel = false;
    auto b = choose_layers(sphere(), p);
    ASSERT_TRUE(a && b);
    ASSERT_EQ(a->layers.size(), b->layers.size());
    for (std::size_t i = 0; i < a->layers.size(); ++i) {
      EXPECT_EQ(a->layers[i].z_bottom_mm, b->layers[i].z_bottom_mm);
      EXPECT_EQ(a->layers[i].thickness_mm, b->layers[i].thickness_mm);
      EXPECT_EQ(a->layers[i].estimated_deviation_mm, b->layers[i].estimated_deviation_mm);
      EXPECT_EQ(a->layers[i].within_tolerance, b->layers[i].within_tolerance);
    }
    EXPECT_EQ(a->shortfalls.size(), b->shortfalls.size());
    EXPECT_EQ(a->warnings, b->warnings);
    EXPECT_EQ(a->stack_height_mm, b->stack_height_mm);
  }
}

TEST(LayeringSphere, RaisedModelLayersFromItsOwnBottom) {
  // The mesh is in the build frame (lowest point at z = 0); the layering starts there.
  const Mesh m = build(mesh_test::uv_sphere(20, 64, 32, {5, -3, 40}));
  const auto p = sphere_params(LayeringMethod::optimal, 0.5);
  auto r = choose_layers(m, p);
  ASSERT_TRUE(r.has_value());
  expect_well_formed(*r, p, m.summary.bbox_min_mm.z());
  EXPECT_NEAR(r->model_height_mm, 40.0, 1e-4);
}

}  // namespace
}  // namespace lamina
