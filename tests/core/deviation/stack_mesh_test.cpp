// stack_mesh and binary_stl_bytes: the shells, written as binary STL, read back and built as a
// mesh, must be closed 2-manifolds (one shell per layer outline group) of the expected volume.
#include "hand_plans.hpp"
#include "lamina/core/deviation.hpp"
#include "lamina/core/mesh.hpp"
#include "lamina/core/mesh_io.hpp"
#include "lamina/core/stack_mesh.hpp"
#include "mesh_checks.hpp"
#include "mesh_soups.hpp"
#include "shapes.hpp"

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstring>
#include <numbers>

namespace lamina {
namespace {

using dev_test::circle_outline;
using dev_test::disc_layer;
using dev_test::make_layer;
using dev_test::ngon_frustum_volume;
using test::regular_polygon_area;

BevelPlan stack_plan_of(std::vector<LayerPlan> layers) {
  BevelPlan plan;
  plan.layers = std::move(layers);
  return plan;
}

// stack_mesh → STL bytes → parse_stl → build_mesh, checked: no open or non-manifold edges.
Mesh reload(const BevelPlan& plan) {
  const TriangleSoup soup = stack_mesh(plan);
  const std::string bytes = binary_stl_bytes(soup, "lamina stack test");
  EXPECT_EQ(bytes.size(), 84 + 50 * soup.triangle_count());
  auto parsed = parse_stl(std::as_bytes(std::span(bytes.data(), bytes.size())), "stack.stl");
  EXPECT_TRUE(parsed.has_value()) << (parsed ? "" : parsed.error().message);
  if (!parsed) return {};
  EXPECT_EQ(parsed->format, "stl-binary");
  EXPECT_EQ(parsed->triangle_count(), soup.triangle_count());
  Mesh mesh = mesh_test::build_checked(*parsed);
  EXPECT_EQ(mesh.find_defect("open_edges"), nullptr) << mesh.find_defect("open_edges")->message;
  EXPECT_EQ(mesh.find_defect("nonmanifold_edges"), nullptr) << mesh.find_defect("nonmanifold_edges")->message;
  EXPECT_TRUE(mesh.summary.watertight);
  return mesh;
}

// Soup volume in the soup's own frame (build_mesh moves the lowest point to z = 0, which does
// not change a closed mesh's volume either).
double volume(const TriangleSoup& s) { return test::soup_volume(s); }

TEST(StlWriter, HeaderAndLayout) {
  TriangleSoup soup;
  soup.corners = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {0, 1, 1}};
  for (const std::string& header : std::vector<std::string>{"solid lamina", "  SOLID x", "stack", std::string(120, 'x')}) {
    const std::string bytes = binary_stl_bytes(soup, header);
    ASSERT_EQ(bytes.size(), 84u + 100u);
    std::string lower = bytes.substr(0, 80);
    const auto first = lower.find_first_not_of(" \t\r\n");
    for (auto& c : lower) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    EXPECT_NE(lower.compare(first, 5, "solid"), 0) << header;
    std::uint32_t count = 0;
    for (int k = 0; k < 4; ++k) count |= static_cast<std::uint32_t>(static_cast<unsigned char>(bytes[80 + k])) << (8 * k);
    EXPECT_EQ(count, 2u);
  }
  // Facet 0: normal +z from the winding, then the corners, little-endian float32.
  const std::string bytes = binary_stl_bytes(soup, "t");
  auto f32 = [&](std::size_t at) {
    std::uint32_t u = 0;
    for (int k = 0; k < 4; ++k) u |= static_cast<std::uint32_t>(static_cast<unsigned char>(bytes[at + k])) << (8 * k);
    return std::bit_cast<float>(u);
  };
  EXPECT_EQ(f32(84 + 8), 1.0f);
  EXPECT_EQ(f32(84 + 12 + 12), 1.0f);  // corner b.x
  EXPECT_EQ(bytes[84 + 48], 0);
  EXPECT_EQ(bytes[84 + 49], 0);
  auto back = parse_stl(std::as_bytes(std::span(bytes.data(), bytes.size())), "t.stl");
  ASSERT_TRUE(back.has_value());
  EXPECT_EQ(back->corners, soup.corners);
}

TEST(StackMesh, VerticalDiscIsItsPrism) {
  const int n = 90;
  const BevelPlan plan = stack_plan_of({disc_layer(0, 1.0, 3.0, 25.0, n)});
  const Mesh mesh = reload(plan);
  EXPECT_EQ(mesh.summary.shells, 1);
  const double v = regular_polygon_area(n, 25.0) * 3.0;
  EXPECT_NEAR(volume(stack_mesh(plan)), v, 1e-5 * v);
  EXPECT_NEAR(mesh.summary.volume_mm3, v, 1e-5 * v);
}

TEST(StackMesh, SlopedLayersAndAHole) {
  const int n = 72;
  // Layer 0: a frustum 20 → 16 with a hole 6 → 8 (widening upwards); layer 1, 0.3 mm above, a
  // prism of radius 16 with a hole of radius 8.
  const BevelPlan plan = stack_plan_of({
      make_layer(0, 0.0, 4.0,
                 {circle_outline(20.0, n, {{20.0, 16.0}}, 0.0, 4.0), circle_outline(6.0, n, {{6.0, 8.0}}, 0.0, 4.0, true, 0)},
                 {0.001, 1.0, 2.0, 3.0, 3.999}),
      make_layer(1, 4.3, 2.0,
                 {circle_outline(16.0, n, {{16.0, 16.0}}, 4.3, 6.3), circle_outline(8.0, n, {{8.0, 8.0}}, 4.3, 6.3, true, 0)}),
  });
  const Mesh mesh = reload(plan);
  EXPECT_EQ(mesh.summary.shells, 2);
  const double v = ngon_frustum_volume(n, 20.0, 16.0, 4.0) - ngon_frustum_volume(n, 6.0, 8.0, 4.0) +
                   (regular_polygon_area(n, 16.0) - regular_polygon_area(n, 8.0)) * 2.0;
  EXPECT_NEAR(volume(stack_mesh(plan)), v, 1e-5 * v);

  // The sections integrated by measure_deviation give the same solid.
  const Mesh model = mesh_test::build_checked(mesh_test::cylinder(20.0, 6.3, n));
  DeviationParams p;
  p.step_mm = 0.05;
  const auto d = measure_deviation(model, plan, p);
  ASSERT_TRUE(d.has_value()) << d.error().message;
  EXPECT_NEAR(d->stack_volume_mm3, v, 1e-4 * v);
}

TEST(StackMesh, CurvedFormKinkIsARing) {
  // Two passes crossing at mid-height (radius 20 → 22 → 20): the ring heights include the
  // midpoint between the layer's faces, where the envelope kinks, so the shell is exactly two
  // n-gon frusta.
  const int n = 64;
  const BevelPlan plan =
      stack_plan_of({make_layer(0, 0.0, 4.0, {circle_outline(20.0, n, {{20.0, 24.0}, {24.0, 20.0}}, 0.0, 4.0)}, {0.001, 3.999})});
  reload(plan);
  const double v = 2.0 * ngon_frustum_volume(n, 20.0, 22.0, 2.0);
  EXPECT_NEAR(volume(stack_mesh(plan)), v, 1e-6 * v);
}

// Issue 17, item 8: every wall was meshed in rows at every sub-slice and midpoint (0.25 mm), so
// a 2,174-triangle model's stack.stl had 1.2 M triangles. A wall that is one straight cut needs
// its two faces only; a wall whose cuts kink keeps a ring there.
TEST(StackMesh, AStraightCutWallIsOneRowAndAKinkedOneKeepsItsKink) {
  const int n = 64;
  // One sloped cut (20 → 16) read from ten sub-slices: walls 2·n triangles, caps 2·(n − 2).
  std::vector<double> subs;
  for (int k = 0; k <= 10; ++k) subs.push_back(k == 0 ? 0.001 : k == 10 ? 4.999 : 0.5 * k);
  const BevelPlan straight = stack_plan_of({make_layer(0, 0.0, 5.0, {circle_outline(20.0, n, {{20.0, 16.0}}, 0.0, 5.0)}, subs)});
  reload(straight);
  EXPECT_EQ(stack_mesh(straight).triangle_count(), static_cast<std::size_t>(2 * n + 2 * (n - 2)));
  const double v = ngon_frustum_volume(n, 20.0, 16.0, 5.0);
  EXPECT_NEAR(volume(stack_mesh(straight)), v, 1e-6 * v);

  // Two crossing cuts (20 → 22 → 20): two rows of walls, the kink at mid-height kept.
  const BevelPlan kinked =
      stack_plan_of({make_layer(0, 0.0, 5.0, {circle_outline(20.0, n, {{20.0, 24.0}, {24.0, 20.0}}, 0.0, 5.0)}, subs)});
  reload(kinked);
  EXPECT_EQ(stack_mesh(kinked).triangle_count(), static_cast<std::size_t>(4 * n + 2 * (n - 2)));
  const double vk = 2.0 * ngon_frustum_volume(n, 20.0, 22.0, 2.5);
  EXPECT_NEAR(volume(stack_mesh(kinked)), vk, 1e-6 * vk);
}

TEST(StackMesh, SeveralPartsInOneLayer) {
  const int n = 40;
  const Eigen::Vector2d a(-30, 0), b(30, 0);
  const BevelPlan plan = stack_plan_of({make_layer(
      0, 0.0, 2.0,
      {circle_outline(10.0, n, {{10.0, 9.0}}, 0.0, 2.0, false, -1, a), circle_outline(3.0, n, {{3.0, 3.0}}, 0.0, 2.0, true, 0, a),
       circle_outline(12.0, n, {{12.0, 12.0}}, 0.0, 2.0, false, -1, b),
       circle_outline(2.0, n, {{2.0, 2.0}}, 0.0, 2.0, true, 2, b + Eigen::Vector2d(5, 0)),
       circle_outline(2.0, n, {{2.0, 2.0}}, 0.0, 2.0, true, 2, b - Eigen::Vector2d(5, 0))})});
  const Mesh mesh = reload(plan);
  EXPECT_EQ(mesh.summary.shells, 2);
  const double v = ngon_frustum_volume(n, 10.0, 9.0, 2.0) - regular_polygon_area(n, 3.0) * 2.0 +
                   (regular_polygon_area(n, 12.0) - 2.0 * regular_polygon_area(n, 2.0)) * 2.0;
  EXPECT_NEAR(volume(stack_mesh(plan)), v, 1e-5 * v);
}

TEST(StackMesh, CollapsingPinStaysClosed) {
  // A pin of radius 3 whose lines reach the axis at mid-layer and cross it: the rings are clamped
  // (pulled back to the last clean ring), so the shell stays closed; it holds at least the true
  // cone (up to the collapse) and at most that plus a thin stub above.
  const int n = 48;
  const BevelPlan plan =
      stack_plan_of({make_layer(0, 0.0, 2.0, {circle_outline(3.0, n, {{3.0, -3.0}}, 0.0, 2.0)}, {0.001, 0.5, 1.0, 1.5, 1.999})});
  const Mesh mesh = reload(plan);
  EXPECT_EQ(mesh.summary.shells, 1);
  const double v = volume(stack_mesh(plan));
  const double cone = ngon_frustum_volume(n, 3.0, 0.0, 1.0);
  EXPECT_GE(v, cone * (1 - 1e-6));
  EXPECT_LE(v, cone + regular_polygon_area(n, 0.75) * 1.25 + 1e-6);
}

TEST(StackMesh, SwallowtailCornersStayClosed) {
  // A square with two stations per corner and every line moved inward by 1.5 (the rings cross
  // themselves at each corner at every height): closed and manifold, volume between the clean
  // cut (the shrunken square prism) and the uncut square prism.
  const double a = 10.0, d = 1.5;
  std::vector<Eigen::Vector2d> base, normals;
  const Eigen::Vector2d corners[4] = {{0, 0}, {a, 0}, {a, a}, {0, a}};
  const Eigen::Vector2d side_normals[4] = {{0, -1}, {1, 0}, {0, 1}, {-1, 0}};
  for (int side = 0; side < 4; ++side)
    for (int k = 0; k <= 5; ++k) {
      base.push_back(corners[side] + (corners[(side + 1) % 4] - corners[side]) * (k / 5.0));
      normals.push_back(side_normals[side]);
    }
  const BevelPlan plan = stack_plan_of({make_layer(
      0, 0.0, 1.0,
      {dev_test::make_outline(base, normals, 1, [&](int, std::size_t) { return dev_test::Offsets{-d, -d * 0.5}; }, 0.0, 1.0)})});
  const Mesh mesh = reload(plan);
  EXPECT_EQ(mesh.summary.shells, 1);
  const double v = volume(stack_mesh(plan));
  EXPECT_GE(v, (a - 2 * d) * (a - 2 * d) * 1.0 - 1e-9);
  EXPECT_LE(v, a * a * 1.0);
}

TEST(StackMesh, CurvedFormSphereLayersAreClosedShells) {
  // Layers of a sphere cut with several tangent lines per station (a curved-form plan built by
  // hand): every layer its own closed shell, and the shells' volume close to the sections'.
  const double R = 12.0, t = 1.5;
  const int n = 120;
  std::vector<LayerPlan> layers;
  for (int i = 0; (i + 1) * t <= 2 * R + 1e-9; ++i) {
    const double zb = i * t + 0.1 * i, zt = zb + t;  // 0.1 mm bonds
    const double zc_lo = i * t, zc_hi = zc_lo + t;    // the part of the sphere this layer stands for
    std::vector<double> subs;
    std::vector<std::pair<double, double>> lines;
    double rho_max = 0.0;
    for (int j = 0; j <= 3; ++j) {
      const double zc = std::clamp(zc_lo + j * t / 3.0, 0.3, 2 * R - 0.3);
      const double w = zc - R, rho = std::sqrt(R * R - w * w);
      rho_max = std::max(rho_max, rho);
      auto at = [&](double z) { return std::min((R * R - w * (z - R)) / rho, rho + 2.5 * t); };
      lines.emplace_back(at(zc_lo), at(zc_hi));
      subs.push_back(zb + j * t / 3.0);
    }
    rho_max = std::max(rho_max, std::sqrt(std::max(0.0, R * R - std::pow(std::clamp(R, zc_lo, zc_hi) - R, 2.0))));
    layers.push_back(make_layer(i, zb, t, {circle_outline(rho_max, n, lines, zb, zt)}, subs));
  }
  const BevelPlan plan = stack_plan_of(layers);
  const Mesh mesh = reload(plan);
  EXPECT_EQ(mesh.summary.shells, static_cast<int>(layers.size()));

  const Mesh model = mesh_test::build_checked(test::translated(test::uv_sphere(R, 96, 48), {0, 0, float(R)}));
  DeviationParams p;
  p.step_mm = 0.02;
  const auto d = measure_deviation(model, plan, p);
  ASSERT_TRUE(d.has_value()) << d.error().message;
  // The mesh joins the rings with straight walls between sub-slice heights and their midpoints;
  // the cut edge kinks elsewhere in between, so the mesh is slightly inside the sections.
  const double v = volume(stack_mesh(plan));
  EXPECT_LE(v, d->stack_volume_mm3 * (1 + 1e-4));
  EXPECT_GT(v, d->stack_volume_mm3 * (1 - 5e-3));
}

}  // namespace
}  // namespace lamina
