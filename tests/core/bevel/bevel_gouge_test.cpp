// Issue 17, item 1: outside cuts took part material at sharp convex corners where a face slopes
// (a bracket's slot built along Y: 0.376 mm deep at every corner). Each station's line fits the
// profile in its own plane; between stations the cut runs along the chord, and a corner that
// moves sideways across the layer lies outside that chord. The check samples the model's section
// boundary between stations at many heights (bevel_checks.hpp, deepest_gouge).
#include "lamina/core/bevel.hpp"
#include "lamina/core/mesh.hpp"

#include "bevel_checks.hpp"
#include "mesh_soups.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace lamina {
namespace {

using bevel_test::deepest_gouge;
using bevel_test::uniform_layers;

Mesh build(const TriangleSoup& soup) {
  auto m = build_mesh(soup, MeshParams{});
  EXPECT_TRUE(m.has_value());
  return std::move(*m);
}

// A 20 × 20 block `h` high whose +x face leans in by `lean_deg` from vertical (out when negative):
// its two corners on that face slide along the y = 0 and y = 20 faces as z rises.
TriangleSoup leaning_block(double h, double lean_deg) {
  const float top_x = static_cast<float>(20.0 - h * std::tan(lean_deg * M_PI / 180.0));
  const float hf = static_cast<float>(h);
  const Eigen::Vector3f b0(0, 0, 0), b1(20, 0, 0), b2(20, 20, 0), b3(0, 20, 0);
  const Eigen::Vector3f t0(0, 0, hf), t1(top_x, 0, hf), t2(top_x, 20, hf), t3(0, 20, hf);
  TriangleSoup s;
  mesh_test::add_quad(s, b0, b3, b2, b1);  // bottom, −z
  mesh_test::add_quad(s, t0, t1, t2, t3);  // top, +z
  mesh_test::add_quad(s, b0, b1, t1, t0);  // y = 0
  mesh_test::add_quad(s, b1, b2, t2, t1);  // the leaning face
  mesh_test::add_quad(s, b2, b3, t3, t2);  // y = 20
  mesh_test::add_quad(s, b3, b0, t0, t3);  // x = 0
  return s;
}

BevelPlan plan(const Mesh& mesh, double h, double thickness) {
  BevelParams p;
  auto r = plan_bevels(mesh, uniform_layers(h, thickness), p);
  EXPECT_TRUE(r.has_value()) << (r ? "" : r.error().message);
  return r ? std::move(*r) : BevelPlan{};
}

TEST(BevelGouge, CornersOfALeaningFaceStayInsideTheCuts) {
  for (double lean : {10.0, 20.0, 35.0, -20.0}) {
    SCOPED_TRACE(::testing::Message() << "lean " << lean << "°");
    const Mesh mesh = build(leaning_block(10.0, lean));
    const BevelPlan bp = plan(mesh, 10.0, 5.0);
    ASSERT_EQ(bp.layers.size(), 2u);
    const auto g = deepest_gouge(mesh, bp);
    EXPECT_LE(g.depth_mm, 1e-3) << "part material outside the cuts at " << g.where;
    for (const auto& layer : bp.layers) EXPECT_LE(layer.gouge_left_mm, 1e-3) << "layer " << layer.index;
  }
}

TEST(BevelGouge, ClearingIsReportedAndCountedInTheDeviation) {
  const Mesh mesh = build(leaning_block(10.0, 20.0));
  const BevelPlan bp = plan(mesh, 10.0, 5.0);
  ASSERT_FALSE(bp.layers.empty());
  // The corner slides 1.82 mm across a 5 mm layer: the stations beside it must move out.
  EXPECT_GT(bp.layers[0].gouge_shift_mm, 0.05);
  EXPECT_GE(bp.layers[0].max_deviation_mm, bp.layers[0].gouge_shift_mm - 1e-9);
}

TEST(BevelGouge, VerticalWallsNeedNoClearing) {
  const Mesh mesh = build(mesh_test::box({0, 0, 0}, {20, 20, 10}));
  const BevelPlan bp = plan(mesh, 10.0, 5.0);
  for (const auto& layer : bp.layers) {
    EXPECT_EQ(layer.gouge_shift_mm, 0.0);
    EXPECT_LT(layer.max_deviation_mm, 1e-6);
  }
  EXPECT_LE(deepest_gouge(mesh, bp).depth_mm, 1e-6);
}

}  // namespace
}  // namespace lamina
