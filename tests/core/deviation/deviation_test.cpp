// layer_section and measure_deviation on hand-built plans against faceted solids whose
// differences are known in closed form (regular n-gon sections, tests/support/shapes.hpp).
#include "hand_plans.hpp"
#include "lamina/core/deviation.hpp"
#include "mesh_checks.hpp"
#include "mesh_soups.hpp"
#include "shapes.hpp"

#include "geometry/clipper_bridge.hpp"
#include "lamina/core/model_index.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>

namespace lamina {
namespace {

using dev_test::circle_outline;
using dev_test::disc_layer;
using dev_test::make_layer;
using test::regular_polygon_area;

double net_area(const std::vector<Polygon2>& rings) {
  double a = 0.0;
  for (const auto& r : rings) a += signed_area_mm2(r);
  return a;
}

Deviation measure(const Mesh& mesh, const BevelPlan& plan, DeviationParams params = {}) {
  auto d = measure_deviation(mesh, plan, params);
  EXPECT_TRUE(d.has_value()) << (d ? "" : d.error().message);
  return d ? *d : Deviation{};
}

BevelPlan plan_of(std::vector<LayerPlan> layers) {
  BevelPlan plan;
  plan.layers = std::move(layers);
  return plan;
}

// ---------------------------------------------------------------------------------------------
// layer_section

TEST(LayerSection, SlopedLinesGiveTheRingAtThatHeight) {
  const int n = 48;
  const LayerPlan layer = make_layer(0, 2.0, 4.0, {circle_outline(10.0, n, {{10.0, 6.0}}, 2.0, 6.0)});
  for (const double z : {2.0, 3.0, 4.5, 6.0}) {
    const double r = 10.0 - (z - 2.0);
    const auto rings = layer_section(layer, z);
    ASSERT_EQ(rings.size(), 1u) << z;
    EXPECT_GT(signed_area_mm2(rings[0]), 0.0);
    EXPECT_NEAR(net_area(rings), regular_polygon_area(n, r), 1e-5 * r) << z;  // 1 nm Clipper grid
  }
}

TEST(LayerSection, EdgeIsTheLowerEnvelopeOfThePasses) {
  // Two passes crossing at mid-height: the edge is 20 + 2·min(t, 1 − t).
  const int n = 64;
  const LayerPlan layer = make_layer(0, 0.0, 4.0, {circle_outline(20.0, n, {{20.0, 24.0}, {24.0, 20.0}}, 0.0, 4.0)});
  for (const double t : {0.0, 0.2, 0.5, 0.7, 1.0}) {
    const double r = 20.0 + 4.0 * std::min(t, 1.0 - t);
    EXPECT_NEAR(net_area(layer_section(layer, 4.0 * t)), regular_polygon_area(n, r), 1e-5 * r) << t;
  }
}

TEST(LayerSection, HoleIsClockwiseAndSubtracted) {
  const int n = 40;
  const LayerPlan layer = make_layer(0, 0.0, 2.0,
                                     {circle_outline(20.0, n, {{20.0, 20.0}}, 0.0, 2.0),
                                      circle_outline(5.0, n, {{5.0, 6.0}}, 0.0, 2.0, true, 0)});
  const auto rings = layer_section(layer, 1.0);  // hole radius 5.5 there
  ASSERT_EQ(rings.size(), 2u);
  int holes = 0;
  for (const auto& r : rings) holes += signed_area_mm2(r) < 0.0;
  EXPECT_EQ(holes, 1);
  EXPECT_NEAR(net_area(rings), regular_polygon_area(n, 20.0) - regular_polygon_area(n, 5.5), 3e-4);
}

TEST(LayerSection, RingCutPastItsAxisKeepsNothing) {
  // A pin of radius 2 whose lines lean in by 5 over the layer: it shrinks to a point at t = 0.4
  // and the ring beyond is the circle turned inside out, which keeps no material.
  const int n = 32;
  const LayerPlan layer = make_layer(0, 0.0, 2.0, {circle_outline(2.0, n, {{2.0, -3.0}}, 0.0, 2.0)});
  EXPECT_NEAR(net_area(layer_section(layer, 0.2)), regular_polygon_area(n, 1.5), 2e-5);
  EXPECT_TRUE(layer_section(layer, 1.2).empty());
  EXPECT_TRUE(layer_section(layer, 2.0).empty());
}

TEST(LayerSection, HoleCutPastItsAxisCloses) {
  const int n = 32;
  // Hole of radius 3 whose lines move 8 into it by the top: closed above t = 3/8.
  const LayerPlan layer = make_layer(0, 0.0, 1.0,
                                     {circle_outline(20.0, n, {{20.0, 20.0}}, 0.0, 1.0),
                                      circle_outline(3.0, n, {{3.0, -5.0}}, 0.0, 1.0, true, 0)});
  EXPECT_NEAR(net_area(layer_section(layer, 0.1)), regular_polygon_area(n, 20.0) - regular_polygon_area(n, 2.2), 3e-4);
  EXPECT_NEAR(net_area(layer_section(layer, 0.9)), regular_polygon_area(n, 20.0), 3e-4);
}

TEST(LayerSection, InwardCornersDropTheirSwallowtails) {
  // A square with two stations at each corner (one per side, side normals): moving every line
  // inward by d leaves a loop turned backwards at each corner; the section is the square
  // shrunk by d on every side.
  const double a = 10.0, d = 1.5;
  std::vector<Eigen::Vector2d> base, normals;
  const Eigen::Vector2d corners[4] = {{0, 0}, {a, 0}, {a, a}, {0, a}};
  const Eigen::Vector2d side_normals[4] = {{0, -1}, {1, 0}, {0, 1}, {-1, 0}};
  for (int side = 0; side < 4; ++side) {
    const Eigen::Vector2d& p = corners[side];
    const Eigen::Vector2d& q = corners[(side + 1) % 4];
    for (int k = 0; k <= 4; ++k) {
      base.push_back(p + (q - p) * (k / 4.0));
      normals.push_back(side_normals[side]);
    }
  }
  const LayerOutline o = dev_test::make_outline(
      base, normals, 1, [&](int, std::size_t) { return dev_test::Offsets{-d, -d}; }, 0.0, 1.0);
  const auto rings = layer_section(make_layer(0, 0.0, 1.0, {o}), 0.5);
  ASSERT_EQ(rings.size(), 1u);
  EXPECT_NEAR(net_area(rings), (a - 2 * d) * (a - 2 * d), 1e-9);
}

// ---------------------------------------------------------------------------------------------
// measure_deviation: volume

// A slice's material for the booleans (the deviation's sections, the gouge check): the slicer's
// loops as they are, unless the gap rule closed some, which may cross and are united first.
Loop square_loop(double x0, double y0, double side, bool gap_closed) {
  Loop l;
  l.points = {{x0, y0}, {x0 + side, y0}, {x0 + side, y0 + side}, {x0, y0 + side}};
  l.facets.assign(4, -1);
  l.area_mm2 = side * side;
  l.gap_closed = gap_closed;
  return l;
}

TEST(SliceMaterial, TheSlicersLoopsAreTakenAsTheyAreAndGapClosedOnesUnited) {
  Slice clean;
  clean.loops = {square_loop(0, 0, 10, false), square_loop(20, 0, 10, false)};
  const ClipperLib::Paths as_is = geometry_detail::slice_material(clean);
  ASSERT_EQ(as_is.size(), 2u);
  EXPECT_EQ(as_is[0], geometry_detail::to_clipper(clean.loops[0].points)) << "not rewritten";
  EXPECT_NEAR(geometry_detail::area_mm2(as_is), 200.0, 1e-9);

  // Two chains of an open mesh closed into squares that overlap by 5 x 10: their union, 150 mm².
  Slice open;
  open.loops = {square_loop(0, 0, 10, true), square_loop(5, 0, 10, true)};
  EXPECT_NEAR(geometry_detail::area_mm2(geometry_detail::slice_material(open)), 150.0, 1e-9);
}

TEST(Deviation, StationsOnTheMeshVerticesLeaveOnlyRounding) {
  const double r = 20.0, h = 10.0;
  const int seg = 64;
  const Mesh mesh = mesh_test::build_checked(mesh_test::cylinder(r, h, seg));
  const Deviation d = measure(mesh, plan_of({disc_layer(0, 0.0, h, r, seg)}));
  const double v = regular_polygon_area(seg, r) * h;
  EXPECT_NEAR(d.model_volume_mm3, v, 1e-5 * v);
  EXPECT_NEAR(d.stack_volume_mm3, v, 1e-5 * v);
  EXPECT_LT(d.volume_mm3, 1e-5 * v);  // float rounding of the mesh only
  EXPECT_LT(d.max_mm, 1e-4);
}

TEST(Deviation, FinerStationsShowTheFacetingOfTheMesh) {
  // Stations at 4× the mesh's meridians on the same circle: the stack is the 256-gon prism, which
  // holds the 64-gon one; the difference is their area difference, and the farthest stack point
  // is a station half-way between two meridians, one sagitta off the mesh's wall.
  const double r = 20.0, h = 10.0;
  const int seg = 64;
  const Mesh mesh = mesh_test::build_checked(mesh_test::cylinder(r, h, seg));
  const Deviation d = measure(mesh, plan_of({disc_layer(0, 0.0, h, r, 4 * seg)}));
  const double want = (regular_polygon_area(4 * seg, r) - regular_polygon_area(seg, r)) * h;
  EXPECT_NEAR(d.volume_mm3, want, 2e-3 * want);
  EXPECT_NEAR(d.volume_pct, 100.0 * want / (regular_polygon_area(seg, r) * h), 1e-3);
  EXPECT_NEAR(d.max_mm, r * (1.0 - std::cos(std::numbers::pi / seg)), 1e-4);
}

// A whole plan builds the model's triangle tree once and hands it to the deviation: the answer
// is the one the deviation gets with its own tree, and a tree of another mesh (a STEP plan's
// finer reference) is not used for this one, even a mesh equal to it.
TEST(Deviation, AGivenTreeOfTheMeshGivesTheSameAnswerAndAnotherMeshsIsNotUsed) {
  const double r = 20.0, h = 10.0;
  const Mesh mesh = mesh_test::build_checked(mesh_test::cylinder(r, h, 64));
  const Mesh coarse = mesh_test::build_checked(mesh_test::cylinder(r, h, 8));
  const BevelPlan plan = plan_of({disc_layer(0, 0.0, h, r, 256)});
  const Deviation own = measure(mesh, plan);
  DeviationParams given;
  given.model_index = std::make_shared<const ModelDistanceIndex>(mesh, true);
  ASSERT_TRUE(given.model_index->indexes(mesh));
  const Deviation with = measure(mesh, plan, given);
  EXPECT_EQ(with.max_mm, own.max_mm);
  EXPECT_EQ(with.max_at_mm, own.max_at_mm);
  EXPECT_EQ(with.volume_mm3, own.volume_mm3);
  // The octagon's tree is 20·(1 − cos 22.5°) = 1.52 mm off the 64-gon's wall in places: used by
  // mistake, it would show.
  DeviationParams wrong;
  wrong.model_index = std::make_shared<const ModelDistanceIndex>(coarse, true);
  EXPECT_FALSE(wrong.model_index->indexes(mesh));
  EXPECT_EQ(measure(mesh, plan, wrong).max_mm, own.max_mm);
  const Mesh copy = mesh;
  EXPECT_FALSE(given.model_index->indexes(copy)) << "another object, even an equal one";
}

TEST(Deviation, OversizeRingIsTheAnnulus) {
  const double r = 20.0, R = 21.0, h = 10.0;
  const int seg = 256;
  const Mesh mesh = mesh_test::build_checked(mesh_test::cylinder(r, h, seg));
  const Deviation d = measure(mesh, plan_of({make_layer(0, 0.0, h, {circle_outline(r, 4 * seg, {{R, R}}, 0.0, h)})}));
  const double faceted = (regular_polygon_area(4 * seg, R) - regular_polygon_area(seg, r)) * h;
  EXPECT_NEAR(d.volume_mm3, faceted, 1e-3 * faceted);
  const double round = std::numbers::pi * (R * R - r * r) * h;
  EXPECT_NEAR(d.volume_mm3, round, 5e-3 * round);
  EXPECT_NEAR(d.stack_volume_mm3, regular_polygon_area(4 * seg, R) * h, 1e-4 * R * R * h);
  // Farthest: the stack's wall (or the rim of its top) half-way between two mesh meridians.
  EXPECT_NEAR(d.max_mm, R - r * std::cos(std::numbers::pi / seg), 1e-3);
}

TEST(Deviation, SlopedLinesFollowAFrustum) {
  const double r0 = 20.0, r1 = 12.0, h = 10.0;
  const int seg = 64;
  const Mesh mesh = mesh_test::build_checked(dev_test::frustum(r0, r1, h, seg));
  // Two layers meeting at z = 4 (no bond), lines on the frustum's meridians.
  const double rm = r0 + (r1 - r0) * 0.4;
  const BevelPlan plan = plan_of({make_layer(0, 0.0, 4.0, {circle_outline(r0, seg, {{r0, rm}}, 0.0, 4.0)}),
                                  make_layer(1, 4.0, 6.0, {circle_outline(rm, seg, {{rm, r1}}, 4.0, h)})});
  const Deviation d = measure(mesh, plan);
  const double v = dev_test::ngon_frustum_volume(seg, r0, r1, h);
  EXPECT_NEAR(d.model_volume_mm3, v, 1e-5 * v);
  EXPECT_NEAR(d.stack_volume_mm3, v, 1e-4 * v);  // midpoint rule on a quadratic area: O(step²)
  EXPECT_LT(d.volume_mm3, 1e-4 * v);
  EXPECT_LT(d.max_mm, 1e-4);

  // The same frustum cut with vertical edges at each layer's bottom outline: the stack is two
  // prisms standing out of the cone; the difference is their volume minus the cone's.
  const BevelPlan vertical = plan_of({disc_layer(0, 0.0, 4.0, r0, seg), disc_layer(1, 4.0, 6.0, rm, seg)});
  const Deviation dv = measure(mesh, vertical);
  const double prisms = regular_polygon_area(seg, r0) * 4.0 + regular_polygon_area(seg, rm) * 6.0;
  EXPECT_NEAR(dv.volume_mm3, prisms - v, 1e-3 * (prisms - v));
  // Largest distance: the top rim of a layer, straight out from the cone's wall below it.
  const double slope = (r0 - r1) / h;  // inward per mm of height
  const double rim = 4.0 * slope * std::cos(std::atan(slope));
  EXPECT_NEAR(dv.max_mm, std::max(rim, 6.0 * slope * std::cos(std::atan(slope))), 2e-3);
}

TEST(Deviation, KinkOfTheEnvelopeIsSampled) {
  // Two passes over a 4 mm layer, radius 20 → 23 and 22 → 20: the edge bulges to 21.2 at
  // z = 1.6, between the 0.5 mm sampling heights. The farthest stack point is that kink, on every
  // station (stations on the cylinder's meridians).
  const double r = 20.0, h = 4.0;
  const int seg = 72;
  const Mesh mesh = mesh_test::build_checked(mesh_test::cylinder(r, h, seg));
  const BevelPlan plan = plan_of({make_layer(0, 0.0, h, {circle_outline(r, seg, {{20.0, 23.0}, {22.0, 20.0}}, 0.0, h)})});
  const Deviation d = measure(mesh, plan);
  EXPECT_NEAR(d.max_mm, 1.2, 1e-4);
  EXPECT_NEAR(d.max_at_mm.z(), 1.6, 1e-6);
  EXPECT_NEAR(std::hypot(d.max_at_mm.x(), d.max_at_mm.y()), 21.2, 1e-6);
  const double stack = dev_test::ngon_frustum_volume(seg, 20.0, 21.2, 1.6) + dev_test::ngon_frustum_volume(seg, 21.2, 20.0, 2.4);
  const double model = regular_polygon_area(seg, r) * h;
  EXPECT_NEAR(d.volume_mm3, stack - model, 2e-3 * (stack - model));
}

TEST(Deviation, BondGapShowsUpAsMissingVolume) {
  const double r = 20.0, h = 10.0;
  const int seg = 64;
  const Mesh mesh = mesh_test::build_checked(mesh_test::cylinder(r, h, seg));
  // Layers 0 … 4.9 and 5.1 … 10: the model's 0.2 mm in between is not in the stack. A step of
  // 0.3 mm puts the gap's faces between sections: they must still be integrated exactly.
  const BevelPlan plan = plan_of({disc_layer(0, 0.0, 4.9, r, seg), disc_layer(1, 5.1, 4.9, r, seg)});
  DeviationParams p;
  p.step_mm = 0.3;
  const Deviation d = measure(mesh, plan, p);
  const double a = regular_polygon_area(seg, r);
  EXPECT_NEAR(d.volume_mm3, 0.2 * a, 1e-3 * 0.2 * a);
  EXPECT_NEAR(d.stack_volume_mm3, 9.8 * a, 1e-5 * 9.8 * a);
  EXPECT_NEAR(d.volume_pct, 2.0, 2e-3);
  EXPECT_LE(d.max_mm, 0.1 + 1e-4);
}

TEST(Deviation, ModelAboveTheStackIsFarAndMissing) {
  const double r = 20.0, h = 10.0;
  const int seg = 64;
  const Mesh mesh = mesh_test::build_checked(mesh_test::cylinder(r, h, seg));
  const Deviation d = measure(mesh, plan_of({disc_layer(0, 0.0, 4.0, r, seg)}));
  const double a = regular_polygon_area(seg, r);
  EXPECT_NEAR(d.volume_mm3, 6.0 * a, 1e-4 * 6.0 * a);
  EXPECT_NEAR(d.max_mm, 6.0, 1e-4);  // the model's top centre to the stack's top face
}

// Issue 17, item 8: a nosecone's max_mm read 0.500 where the true largest distance was 0.528,
// on the last layer's top face, off the axis: the face was sampled on a 0.5 mm grid and its
// farthest point lay between grid points. Here a block whose top is a V-groove along y, its
// bottom at x = 0.3 (between the grid's columns, ±0.25 mm from it), 1 mm deep, under a flat layer
// top: the farthest point of the stack's face is above the groove's bottom, 1·cos(atan(1/10.3))
// from the groove's sides (no model vertex lies under it: they are at the block's ends).
TEST(Deviation, AFacesFarthestPointBetweenGridPointsIsFound) {
  const double x0 = 0.3, depth = 1.0;
  TriangleSoup soup;
  auto v = [](double x, double y, double z) { return Eigen::Vector3f(float(x), float(y), float(z)); };
  auto tri = [&](Eigen::Vector3f a, Eigen::Vector3f b, Eigen::Vector3f c) { soup.corners.insert(soup.corners.end(), {a, b, c}); };
  auto quad = [&](Eigen::Vector3f a, Eigen::Vector3f b, Eigen::Vector3f c, Eigen::Vector3f d) { tri(a, b, c), tri(a, c, d); };
  const double h = 10.0, g = h - depth;
  quad(v(-10, -10, 0), v(-10, 10, 0), v(10, 10, 0), v(10, -10, 0));        // bottom, facing down
  quad(v(-10, -10, h), v(x0, -10, g), v(x0, 10, g), v(-10, 10, h));        // the groove's left side
  quad(v(x0, -10, g), v(10, -10, h), v(10, 10, h), v(x0, 10, g));          // its right side
  quad(v(-10, -10, 0), v(10, -10, 0), v(10, -10, h), v(-10, -10, h));      // y = -10
  tri(v(-10, -10, h), v(10, -10, h), v(x0, -10, g));
  quad(v(10, 10, 0), v(-10, 10, 0), v(-10, 10, h), v(10, 10, h));          // y = +10
  tri(v(10, 10, h), v(-10, 10, h), v(x0, 10, g));
  quad(v(-10, 10, 0), v(-10, -10, 0), v(-10, -10, h), v(-10, 10, h));      // x = -10
  quad(v(10, -10, 0), v(10, 10, 0), v(10, 10, h), v(10, -10, h));          // x = +10
  const Mesh mesh = mesh_test::build_checked(soup);
  ASSERT_TRUE(mesh.summary.watertight);
  const Deviation d = measure(mesh, plan_of({make_layer(0, 0.0, h, {dev_test::square_outline({0, 0}, 10.0, 0.0, h)})}));
  // The truth, in the groove's cross-section: the largest over the face (z = h) of the distance
  // to the two sides, by dense search.
  auto segment_distance = [](Eigen::Vector2d p, Eigen::Vector2d a, Eigen::Vector2d b) {
    const double t = std::clamp((p - a).dot(b - a) / (b - a).squaredNorm(), 0.0, 1.0);
    return (p - (a + t * (b - a))).norm();
  };
  double truth = 0.0;
  for (double x = -10.0; x <= 10.0; x += 1e-5) {
    const Eigen::Vector2d p(x, h);
    truth = std::max(truth, std::min(segment_distance(p, {-10, h}, {x0, g}), segment_distance(p, {x0, g}, {10, h})));
  }
  EXPECT_NEAR(truth, 0.995, 1e-3);
  EXPECT_NEAR(d.max_mm, truth, 2e-4) << "found at " << d.max_at_mm.transpose();
}

TEST(Deviation, SphereWithCurvedFormLayers) {
  // A UV sphere, layers of 2 mm whose edge is two tangent lines per station (at the layer's
  // faces, outside the sphere): the symmetric difference is small and the stack holds the model.
  const double R = 15.0;
  const int seg = 96, rings = 48;
  const Mesh mesh = mesh_test::build_checked(test::translated(test::uv_sphere(R, seg, rings), {0, 0, float(R)}));
  std::vector<LayerPlan> layers;
  const double t = 2.0;
  for (int i = 0; i * t < 2 * R - 1e-9; ++i) {
    const double zb = i * t, zt = std::min(2 * R, zb + t);
    // Tangent of the circle ρ(z) = sqrt(R² − (z − R)²) at height zc, evaluated at z.
    auto tangent = [&](double zc, double z) {
      const double w = zc - R;
      const double rho = std::sqrt(std::max(R * R - w * w, 0.0));
      return (R * R - w * (z - R)) / std::max(rho, 1e-9);  // the tangent line's radius at z
    };
    const double zc0 = std::clamp(zb, 0.05, 2 * R - 0.05), zc1 = std::clamp(zt, 0.05, 2 * R - 0.05);
    const double rho_max = std::sqrt(std::max(R * R - std::pow(std::clamp(R, zb, zt) - R, 2.0), 0.0));
    std::vector<std::pair<double, double>> lines{{tangent(zc0, zb), tangent(zc0, zt)}, {tangent(zc1, zb), tangent(zc1, zt)}};
    // Stations on the layer's widest circle; lines as radii. Limit the pole layers' lines to a
    // sane tilt (they would be nearly horizontal).
    for (auto& [rb, rt] : lines) {
      rb = std::min(rb, rho_max + 3 * t);
      rt = std::min(rt, rho_max + 3 * t);
    }
    layers.push_back(make_layer(i, zb, zt - zb, {circle_outline(std::max(rho_max, 0.5), 4 * seg, lines, zb, zt)}));
  }
  const Deviation d = measure(mesh, plan_of(layers));
  EXPECT_GT(d.stack_volume_mm3, d.model_volume_mm3);
  EXPECT_LT(d.volume_pct, 5.0);
  EXPECT_GT(d.volume_pct, 0.01);
  EXPECT_GE(d.volume_mm3, d.stack_volume_mm3 - d.model_volume_mm3 - 1e-6 * d.model_volume_mm3);
  EXPECT_LT(d.max_mm, 3.0);
  EXPECT_GT(d.max_mm, 0.05);
}

TEST(Deviation, ThreadsDoNotChangeTheResult) {
  const Mesh mesh = mesh_test::build_checked(dev_test::frustum(20.0, 14.0, 8.0, 48));
  const BevelPlan plan = plan_of({make_layer(0, 0.0, 3.9, {circle_outline(20.0, 100, {{20.5, 17.0}, {21.0, 16.9}}, 0.0, 3.9)}),
                                  make_layer(1, 4.0, 4.0, {circle_outline(17.0, 100, {{17.2, 14.1}}, 4.0, 8.0)})});
  DeviationParams serial;
  serial.parallel = false;
  const Deviation a = measure(mesh, plan, serial);
  const Deviation b = measure(mesh, plan, DeviationParams{});
  EXPECT_EQ(a.volume_mm3, b.volume_mm3);
  EXPECT_EQ(a.stack_volume_mm3, b.stack_volume_mm3);
  EXPECT_EQ(a.max_mm, b.max_mm);
  EXPECT_GT(a.volume_mm3, 0.0);
}

TEST(Deviation, RejectsWhatItCannotMeasure) {
  const Mesh mesh = mesh_test::build_checked(mesh_test::cylinder(5.0, 2.0, 16));
  const BevelPlan plan = plan_of({disc_layer(0, 0.0, 2.0, 5.0, 16)});
  DeviationParams p;
  p.step_mm = 0.0;
  EXPECT_FALSE(measure_deviation(mesh, plan, p).has_value());
  p = {};
  p.distance_sample_mm = std::nan("");
  EXPECT_FALSE(measure_deviation(mesh, plan, p).has_value());
  EXPECT_FALSE(measure_deviation(mesh, BevelPlan{}, {}).has_value());
  BevelPlan broken = plan;
  broken.layers[0].outlines[0].passes[0].lines.pop_back();
  const auto e = measure_deviation(mesh, broken, {});
  ASSERT_FALSE(e.has_value());
  EXPECT_EQ(e.error().code, ErrorCode::invalid_argument);
  EXPECT_NE(e.error().message.find("outline 0"), std::string::npos) << e.error().message;
  p = {};
  p.distance_sample_mm = 1e-5;  // billions of wall samples
  EXPECT_FALSE(measure_deviation(mesh, plan, p).has_value());
}

}  // namespace
}  // namespace lamina
