// plan_bevels on solids whose answer is known: a cone (tool axis, tilt, the paper's A and C),
// an overhanging cone, a countersunk hole (sign conventions on holes), a sphere (convex
// multi-cut, tilt limit, continuous C) and a vertical-walled box.
#include "lamina/core/bevel.hpp"
#include "lamina/core/mesh.hpp"

#include "bevel_checks.hpp"
#include "mesh_soups.hpp"
#include "revolve.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace lamina {
namespace {

using test_shapes::RZ;
using test_shapes::revolve;
using bevel_test::uniform_layers;

Mesh usable_mesh(const TriangleSoup& soup) {
  auto m = build_mesh(soup, MeshParams{});
  EXPECT_TRUE(m.has_value());
  EXPECT_TRUE(m->usable());
  return std::move(*m);
}

BevelPlan plan(const Mesh& mesh, const std::vector<LayerSpan>& layers, BevelParams p = {}) {
  auto r = plan_bevels(mesh, layers, p);
  EXPECT_TRUE(r.has_value()) << (r ? "" : r.error().message);
  return std::move(*r);
}

double radial_component(const CutLine& l, const Eigen::Vector2d& at) {
  return l.tool_axis.head<2>().dot(at.normalized());
}

TEST(BevelShapes, ConeLeansTheToolInwardAtTheSurfaceAngle) {
  // Cone R 30 at the base, apex at z = 40: the surface is atan(30/40) from vertical.
  const Mesh mesh = usable_mesh(revolve({{0, 0}, {30, 0}, {0, 40}}, 96));
  const double slope_rad = std::atan2(30.0, 40.0);
  const auto p = plan(mesh, {{5.0, 10.0, 0, true}});
  ASSERT_EQ(p.layers.size(), 1u);
  const auto& layer = p.layers[0];
  ASSERT_EQ(layer.outlines.size(), 1u);
  const auto& outline = layer.outlines[0];
  EXPECT_FALSE(outline.is_hole);
  EXPECT_EQ(outline.passes.size(), 1u) << "a straight flank needs one cut";
  EXPECT_EQ(layer.shape_counts[static_cast<int>(ProfileShape::straight)], static_cast<int>(outline.stations.size()));
  EXPECT_LT(layer.max_deviation_mm, 1e-3);
  for (std::size_t i = 0; i < outline.stations.size(); ++i) {
    const auto& st = outline.stations[i];
    const auto& l = outline.passes[0].lines[i];
    EXPECT_NEAR(l.tilt_rad, slope_rad, 1e-3);
    EXPECT_LT(radial_component(l, st.base_mm), -0.5) << "the nozzle leans towards the cone's axis";
    // The paper's V is the upward surface tangent: here the tool axis itself.
    EXPECT_NEAR(l.paper_v.dot(l.tool_axis), 1.0, 1e-3);
    EXPECT_NEAR(l.paper_a_deg, 180.0 - slope_rad * 180.0 / M_PI, 0.1);
    // Top and bottom points on the cone: r(z) = 30 (1 − z/40), up to the faceting (cos π/96).
    EXPECT_NEAR(l.top_mm.head<2>().norm(), 30.0 * (1 - 15.0 / 40), 0.02);
    EXPECT_NEAR(l.bottom_mm.head<2>().norm(), 30.0 * (1 - 5.0 / 40), 0.02);
    // C points from the station towards the axis.
    const double expected_c = std::atan2(-st.base_mm.y(), -st.base_mm.x());
    EXPECT_NEAR(std::remainder(l.c_rad - expected_c, 2 * M_PI), 0.0, 0.05);
    EXPECT_NEAR(std::remainder(l.paper_c_deg * M_PI / 180.0 - expected_c, 2 * M_PI), 0.0, 0.05);
  }
}

TEST(BevelShapes, OverhangLeansTheToolOutward) {
  // An inverted cone (narrow at the bottom): the flank overhangs, the nozzle leans out.
  const Mesh mesh = usable_mesh(revolve({{0, 0}, {10, 0}, {30, 20}, {0, 20}}, 96));
  const auto p = plan(mesh, {{5.0, 10.0, 0, true}});
  const auto& outline = p.layers.at(0).outlines.at(0);
  for (std::size_t i = 0; i < outline.stations.size(); ++i) {
    const auto& l = outline.passes[0].lines[i];
    EXPECT_GT(radial_component(l, outline.stations[i].base_mm), 0.5);
    EXPECT_NEAR(l.tilt_rad, M_PI / 4, 1e-3);
  }
}

TEST(BevelShapes, CountersunkHoleLeansAwayFromItsAxis) {
  // A disc R 30, 10 thick, with a bore widening from r 5 at the bottom to r 8 at the top.
  const Mesh mesh = usable_mesh(revolve({{5, 0}, {30, 0}, {30, 10}, {8, 10}}, 96));
  const auto p = plan(mesh, {{0.0, 10.0, 0, true}});
  const auto& layer = p.layers.at(0);
  ASSERT_EQ(layer.outlines.size(), 2u);
  int holes = 0;
  for (const auto& outline : layer.outlines) {
    if (!outline.is_hole) {
      for (const auto& l : outline.passes[0].lines) EXPECT_NEAR(l.tilt_rad, 0.0, 1e-6);
      continue;
    }
    ++holes;
    EXPECT_GE(outline.parent, 0);
    EXPECT_FALSE(layer.outlines[static_cast<std::size_t>(outline.parent)].is_hole);
    ASSERT_EQ(outline.passes.size(), 1u);
    for (std::size_t i = 0; i < outline.stations.size(); ++i) {
      const auto& st = outline.stations[i];
      const auto& l = outline.passes[0].lines[i];
      EXPECT_LT(st.normal.dot(st.base_mm.normalized()), -0.9) << "hole normals point into the hole";
      EXPECT_GT(radial_component(l, st.base_mm), 0.1) << "the bore widens upward: the nozzle leans out";
      EXPECT_NEAR(l.tilt_rad, std::atan(0.3), 2e-3);
      EXPECT_NEAR(l.paper_v.dot(l.tool_axis), 1.0, 1e-3) << "eq. 1 on a hole gives the same tangent";
      EXPECT_NEAR(l.top_mm.head<2>().norm(), 8.0, 0.01);
      EXPECT_NEAR(l.bottom_mm.head<2>().norm(), 5.0, 0.01);
    }
  }
  EXPECT_EQ(holes, 1);
}

TEST(BevelShapes, SphereGetsTangentCutsWithinTheTiltLimitAndContinuousC) {
  const Mesh mesh = usable_mesh(mesh_test::uv_sphere(50.0, 128, 64, Eigen::Vector3d(0, 0, 50)));
  BevelParams params;
  const auto p = plan(mesh, uniform_layers(100.0, 10.0), params);
  ASSERT_EQ(p.layers.size(), 10u);
  const double limit = params.fit.tilt_max_rad;
  int convex = 0, limited = 0;
  for (const auto& layer : p.layers) {
    convex += layer.shape_counts[static_cast<int>(ProfileShape::convex)];
    for (const auto& outline : layer.outlines) {
      for (const auto& st : outline.stations) limited += st.tilt_limited;
      for (const auto& pass : outline.passes) {
        for (std::size_t i = 0; i < pass.lines.size(); ++i) {
          const auto& l = pass.lines[i];
          ASSERT_LE(l.tilt_rad, limit + 1e-9);
          EXPECT_NEAR(l.tool_axis.norm(), 1.0, 1e-12);
          const auto& prev = pass.lines[(i + pass.lines.size() - 1) % pass.lines.size()];
          if (i > 0) {
            EXPECT_LT(std::abs(l.c_rad - prev.c_rad), 0.5) << "C jumps at layer " << layer.index << " station " << i;
          }
        }
      }
    }
  }
  EXPECT_GT(convex, 0);
  EXPECT_GT(limited, 0) << "the pole layers are flatter than 60°";
  // Layers around the equator (30–40, 60–70 mm) are convex and cut once per sub-slice.
  const auto& band = p.layers[3];
  EXPECT_EQ(band.passes, static_cast<int>(band.sub_slice_z_mm.size()));
  EXPECT_GT(band.shape_counts[static_cast<int>(ProfileShape::convex)], static_cast<int>(band.outlines[0].stations.size()) * 9 / 10);
  EXPECT_LT(band.max_deviation_mm, 0.05);
  const auto removed = bevel_test::material_removed(mesh, p, 1e-3);
  EXPECT_EQ(removed.inside, 0u) << removed.first << " (" << removed.points << " points)";
}

TEST(BevelShapes, VerticalStrategyAndBoxWalls) {
  const Mesh box = usable_mesh(mesh_test::box({0, 0, 0}, {40, 20, 12}));
  auto p = plan(box, uniform_layers(12.0, 4.0));
  for (const auto& layer : p.layers) {
    EXPECT_EQ(layer.passes, 1);
    EXPECT_LT(layer.max_deviation_mm, 1e-9);
    for (const auto& l : layer.outlines.at(0).passes.at(0).lines) EXPECT_NEAR(l.tilt_rad, 0.0, 1e-9);
  }
  const Mesh sphere = usable_mesh(mesh_test::uv_sphere(50.0, 64, 32, Eigen::Vector3d(0, 0, 50)));
  BevelParams params;
  params.fit.strategy = BevelStrategy::vertical;
  p = plan(sphere, uniform_layers(100.0, 10.0), params);
  for (const auto& layer : p.layers) {
    EXPECT_EQ(layer.passes, 1);
    for (const auto& o : layer.outlines) {
      for (const auto& l : o.passes[0].lines) EXPECT_NEAR(l.tilt_rad, 0.0, 1e-9);
    }
  }
  const auto removed = bevel_test::material_removed(sphere, p, 1e-3);
  EXPECT_EQ(removed.inside, 0u) << removed.first;
}

TEST(BevelShapes, SerialAndParallelPlansAgree) {
  const Mesh mesh = usable_mesh(mesh_test::uv_sphere(20.0, 48, 24, Eigen::Vector3d(0, 0, 20)));
  BevelParams a, b;
  b.parallel = false;
  const auto pa = plan(mesh, uniform_layers(40.0, 5.0), a);
  const auto pb = plan(mesh, uniform_layers(40.0, 5.0), b);
  ASSERT_EQ(pa.layers.size(), pb.layers.size());
  for (std::size_t i = 0; i < pa.layers.size(); ++i) {
    ASSERT_EQ(pa.layers[i].outlines.size(), pb.layers[i].outlines.size());
    EXPECT_EQ(pa.layers[i].max_deviation_mm, pb.layers[i].max_deviation_mm);
    for (std::size_t o = 0; o < pa.layers[i].outlines.size(); ++o) {
      const auto& x = pa.layers[i].outlines[o].passes.back().lines;
      const auto& y = pb.layers[i].outlines[o].passes.back().lines;
      ASSERT_EQ(x.size(), y.size());
      for (std::size_t k = 0; k < x.size(); ++k) EXPECT_EQ(x[k].top_mm, y[k].top_mm);
    }
  }
}

TEST(BevelShapes, BadParametersAreRejected) {
  const Mesh mesh = usable_mesh(mesh_test::unit_cube());
  BevelParams p;
  p.sub_slice_mm = 0;
  EXPECT_EQ(plan_bevels(mesh, uniform_layers(1, 0.5), p).error().code, ErrorCode::invalid_argument);
  p = {};
  p.fit.tilt_max_rad = M_PI / 2;
  EXPECT_EQ(plan_bevels(mesh, uniform_layers(1, 0.5), p).error().code, ErrorCode::invalid_argument);
  const std::vector<LayerSpan> overlapping{{0, 0.6, 0, true}, {0.5, 0.5, 0, true}};
  EXPECT_EQ(plan_bevels(mesh, overlapping, BevelParams{}).error().code, ErrorCode::invalid_argument);
}

}  // namespace
}  // namespace lamina
