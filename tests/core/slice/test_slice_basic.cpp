// Slicing on solids whose sections are known exactly: boxes, an octahedron, cavities, open and
// non-manifold meshes, overlapping shells.
#include "mesh_checks.hpp"
#include "mesh_soups.hpp"
#include "lamina/core/mesh.hpp"
#include "lamina/core/slice.hpp"

#include <gtest/gtest.h>

#include <limits>
#include <mutex>
#include <set>

namespace lamina {
namespace {

using mesh_test::box;

std::vector<Slice> cut(const Mesh& mesh, std::vector<double> zs, SliceParams p = {}) {
  auto s = slice_mesh(mesh, zs, p);
  EXPECT_TRUE(s.has_value()) << (s ? "" : s.error().message);
  return s ? std::move(*s) : std::vector<Slice>{};
}

TEST(SliceBasic, BoxGivesOneCcwLoopWithFacetAttributes) {
  const Mesh mesh = mesh_test::build_checked(box({0, 0, 0}, {10, 20, 30}));
  const auto slices = cut(mesh, {15.0});
  ASSERT_EQ(slices.size(), 1u);
  const Slice& s = slices[0];
  ASSERT_EQ(s.loops.size(), 1u);
  EXPECT_EQ(s.outer_count(), 1);
  EXPECT_EQ(s.hole_count(), 0);
  EXPECT_NEAR(s.loops[0].area_mm2, 200.0, 1e-9);
  EXPECT_FALSE(s.loops[0].is_hole());
  EXPECT_EQ(s.loops[0].parent, -1);
  // Each side face is two triangles and both cross the plane: 8 vectors.
  EXPECT_EQ(s.loops[0].size(), 8u);
  std::set<int> surfaces;
  for (std::size_t i = 0; i < s.loops[0].size(); ++i) {
    const ContourVector v = s.vector(mesh, 0, i);
    EXPECT_EQ(v.z_mm, 15.0);
    ASSERT_GE(v.facet, 0);
    EXPECT_NEAR(v.normal.norm(), 1.0, 1e-12);
    EXPECT_NEAR(v.normal.z(), 0.0, 1e-12);
    EXPECT_EQ(v.normal, mesh.normals[static_cast<std::size_t>(v.facet)]);
    EXPECT_EQ(v.surface_id, mesh.surface_id[static_cast<std::size_t>(v.facet)]);
    // Outer loops run counter-clockwise: the direction is z × n (material on the left).
    const Eigen::Vector2d d = (v.end_mm - v.start_mm).normalized();
    EXPECT_NEAR(d.x(), -v.normal.y(), 1e-12);
    EXPECT_NEAR(d.y(), v.normal.x(), 1e-12);
    surfaces.insert(v.surface_id);
  }
  EXPECT_EQ(surfaces.size(), 4u) << "four side walls, four surfaces";
}

TEST(SliceBasic, PlaneThroughVerticesFollowsTheAboveRule) {
  // On-plane vertices count as above: the top face plane cuts the walls (full section), the
  // bottom face plane cuts nothing — each plane belongs to exactly one side of a horizontal face.
  const Mesh mesh = mesh_test::build_checked(box({0, 0, 0}, {10, 20, 30}));
  const auto slices = cut(mesh, {0.0, 30.0, 30.0 + 1e-9, -1.0});
  EXPECT_TRUE(slices[0].loops.empty());
  ASSERT_EQ(slices[1].loops.size(), 1u);
  EXPECT_NEAR(slices[1].net_area_mm2(), 200.0, 1e-9);
  EXPECT_TRUE(slices[2].loops.empty());
  EXPECT_TRUE(slices[3].loops.empty());
}

TEST(SliceBasic, OctahedronEquatorThroughFourVertices) {
  TriangleSoup soup;
  const Eigen::Vector3f px(1, 0, 0), nx(-1, 0, 0), py(0, 1, 0), ny(0, -1, 0), pz(0, 0, 1), nz(0, 0, -1);
  for (const auto& t : std::vector<std::array<Eigen::Vector3f, 3>>{
           {px, py, pz}, {py, nx, pz}, {nx, ny, pz}, {ny, px, pz},
           {py, px, nz}, {nx, py, nz}, {ny, nx, nz}, {px, ny, nz}})
    for (const auto& c : t) soup.corners.push_back(c);
  const Mesh mesh = mesh_test::build_checked(soup);
  const auto slices = cut(mesh, {1.0, 0.5, 1.5});
  ASSERT_EQ(slices[0].loops.size(), 1u);
  EXPECT_EQ(slices[0].loops[0].size(), 4u) << "the four lower facets give the diamond, no zero-length vector";
  EXPECT_DOUBLE_EQ(slices[0].net_area_mm2(), 2.0);
  EXPECT_NEAR(slices[1].net_area_mm2(), 0.5, 1e-12);  // half-diagonal 0.5
  EXPECT_NEAR(slices[2].net_area_mm2(), 0.5, 1e-12);
}

TEST(SliceBasic, CavityIsAClockwiseHoleInsideTheOuterLoop) {
  TriangleSoup soup = box({0, 0, 0}, {10, 10, 10});
  soup = mesh_test::append(soup, mesh_test::inverted(box({2, 3, 2}, {6, 8, 8})));
  const Mesh mesh = mesh_test::build_checked(soup);
  const auto s = cut(mesh, {5.0})[0];
  ASSERT_EQ(s.loops.size(), 2u);
  EXPECT_EQ(s.outer_count(), 1);
  EXPECT_EQ(s.hole_count(), 1);
  const Loop& hole = s.loops[0].is_hole() ? s.loops[0] : s.loops[1];
  const Loop& outer = s.loops[0].is_hole() ? s.loops[1] : s.loops[0];
  EXPECT_NEAR(hole.area_mm2, -20.0, 1e-9);
  EXPECT_EQ(hole.depth, 1);
  EXPECT_EQ(outer.depth, 0);
  EXPECT_NE(hole.parent, -1);
  EXPECT_NEAR(s.net_area_mm2(), 80.0, 1e-9);
}

TEST(SliceBasic, OpenMeshChainIsReportedAndClosedByTheGapRule) {
  // Remove one triangle of the +x wall (the box's last quad, facets 10 and 11).
  const TriangleSoup soup = mesh_test::without_facet(box({0, 0, 0}, {10, 20, 30}), 10);
  const Mesh mesh = mesh_test::build_checked(soup);
  EXPECT_FALSE(mesh.usable());

  SliceParams off;
  off.gap_close_mm = 0.0;
  const auto open = cut(mesh, {15.0}, off)[0];
  EXPECT_TRUE(open.loops.empty());
  ASSERT_EQ(open.open_chains.size(), 1u);
  EXPECT_FALSE(open.warnings.empty());

  SliceParams on;
  on.gap_close_mm = 25.0;
  const auto closed = cut(mesh, {15.0}, on)[0];
  ASSERT_EQ(closed.loops.size(), 1u);
  EXPECT_TRUE(closed.loops[0].gap_closed);
  EXPECT_NEAR(closed.net_area_mm2(), 200.0, 1e-9);
  EXPECT_EQ(closed.open_chains.size(), 1u) << "the chain as found stays reported";
  int gap_vectors = 0;
  for (std::size_t i = 0; i < closed.loops[0].size(); ++i)
    if (closed.vector(mesh, 0, i).facet < 0) ++gap_vectors;
  EXPECT_EQ(gap_vectors, 1);
  EXPECT_FALSE(closed.warnings.empty());

  SliceParams too_small;
  too_small.gap_close_mm = 1e-3;
  const auto left_open = cut(mesh, {15.0}, too_small)[0];
  EXPECT_TRUE(left_open.loops.empty());
}

TEST(SliceBasic, BoxesTouchingAlongAnEdgeStayTwoLoops) {
  TriangleSoup soup = box({0, 0, 0}, {1, 1, 1});
  soup = mesh_test::append(soup, box({1, 1, 0}, {2, 2, 1}));
  const Mesh mesh = mesh_test::build_checked(soup);
  const auto s = cut(mesh, {0.5})[0];
  ASSERT_EQ(s.loops.size(), 2u);
  EXPECT_EQ(s.outer_count(), 2);
  EXPECT_NEAR(s.loops[0].area_mm2, 1.0, 1e-12);
  EXPECT_NEAR(s.loops[1].area_mm2, 1.0, 1e-12);
  EXPECT_EQ(s.loops[0].depth, 0);
  EXPECT_EQ(s.loops[1].depth, 0);
}

TEST(SliceBasic, OverlappingShellsSliceToTheirUnion) {
  TriangleSoup soup = box({0, 0, 0}, {10, 10, 10});
  soup = mesh_test::append(soup, box({5, 5, 2}, {15, 15, 8}));
  const Mesh mesh = mesh_test::build_checked(soup);
  const auto slices = cut(mesh, {5.0, 9.0});
  const Slice& both = slices[0];
  ASSERT_EQ(both.loops.size(), 1u);
  EXPECT_NEAR(both.net_area_mm2(), 175.0, 1e-9);
  EXPECT_FALSE(both.warnings.empty());
  for (std::size_t i = 0; i < both.loops[0].size(); ++i) EXPECT_GE(both.vector(mesh, 0, i).facet, 0);
  EXPECT_NEAR(slices[1].net_area_mm2(), 100.0, 1e-9);
  EXPECT_TRUE(slices[1].warnings.empty());
}

TEST(SliceBasic, OverlapCreatingAnEnclosedHole) {
  // Two U-shaped bodies overlapping into a ring: the union has an outer loop and a hole.
  TriangleSoup soup;
  soup = mesh_test::append(soup, box({0, 0, 0}, {10, 3, 5}));   // bottom bar
  soup = mesh_test::append(soup, box({0, 7, 0}, {10, 10, 5}));  // top bar
  soup = mesh_test::append(soup, box({-1, -1, 0}, {3, 11, 5})); // left bar overlapping both
  soup = mesh_test::append(soup, box({7, -1, 0}, {11, 11, 5})); // right bar overlapping both
  const Mesh mesh = mesh_test::build_checked(soup);
  const auto s = cut(mesh, {2.5})[0];
  EXPECT_EQ(s.outer_count(), 1);
  EXPECT_EQ(s.hole_count(), 1);
  // Outer: 12 x 12 minus the two notches (1 x 4 at y<0 and y>10 between x 3..7) → 144 - 8;
  // hole: 4 x 4 between x 3..7, y 3..7.
  EXPECT_NEAR(s.net_area_mm2(), 144.0 - 8.0 - 16.0, 1e-9);
}

TEST(SliceBasic, ParallelAndSerialAgreeAndOrderFollowsInput) {
  TriangleSoup soup = box({0, 0, 0}, {10, 10, 10});
  soup = mesh_test::append(soup, mesh_test::inverted(box({2, 2, 2}, {8, 8, 8})));
  const Mesh mesh = mesh_test::build_checked(soup);
  std::vector<double> zs{9.0, 1.0, 5.0, 3.3, 7.7};
  SliceParams serial;
  serial.parallel = false;
  const auto a = cut(mesh, zs), b = cut(mesh, zs, serial);
  ASSERT_EQ(a.size(), zs.size());
  for (std::size_t i = 0; i < zs.size(); ++i) {
    EXPECT_EQ(a[i].z_mm, zs[i]);
    EXPECT_EQ(a[i].net_area_mm2(), b[i].net_area_mm2());
    EXPECT_EQ(a[i].loops.size(), b[i].loops.size());
  }
  EXPECT_NEAR(a[0].net_area_mm2(), 100.0, 1e-9);
  EXPECT_NEAR(a[2].net_area_mm2(), 64.0, 1e-9);
}

// for_each_slice hands over every height's slice once, by its index in zs, the same slice
// slice_mesh returns; a bad height is refused before any is handed over.
TEST(SliceBasic, EachSliceIsHandedOverOnceByItsIndex) {
  TriangleSoup soup = box({0, 0, 0}, {10, 10, 10});
  soup = mesh_test::append(soup, mesh_test::inverted(box({2, 2, 2}, {8, 8, 8})));
  const Mesh mesh = mesh_test::build_checked(soup);
  std::vector<double> zs{9.0, 1.0, 5.0, 3.3, 7.7, 5.0};
  const auto all = cut(mesh, zs);
  for (const bool parallel : {false, true}) {
    SliceParams p;
    p.parallel = parallel;
    std::vector<int> seen(zs.size(), 0);
    std::vector<double> areas(zs.size(), -1.0), heights(zs.size(), -1.0);
    std::mutex m;
    auto done = for_each_slice(mesh, zs, p, [&](std::size_t i, Slice&& s) {
      const std::lock_guard lock(m);
      ASSERT_LT(i, zs.size());
      ++seen[i];
      areas[i] = s.net_area_mm2();
      heights[i] = s.z_mm;
    });
    ASSERT_TRUE(done);
    for (std::size_t i = 0; i < zs.size(); ++i) {
      EXPECT_EQ(seen[i], 1) << i;
      EXPECT_EQ(heights[i], zs[i]);
      EXPECT_EQ(areas[i], all[i].net_area_mm2());
    }
  }
  std::vector<double> bad{0.5, std::numeric_limits<double>::infinity()};
  int calls = 0;
  EXPECT_FALSE(for_each_slice(mesh, bad, SliceParams{}, [&](std::size_t, Slice&&) { ++calls; }));
  EXPECT_EQ(calls, 0);
}

TEST(SliceBasic, RejectsNonFiniteHeights) {
  const Mesh mesh = mesh_test::build_checked(box({0, 0, 0}, {1, 1, 1}));
  std::vector<double> zs{0.5, std::numeric_limits<double>::quiet_NaN()};
  auto r = slice_mesh(mesh, zs, SliceParams{});
  ASSERT_FALSE(r.has_value());
  EXPECT_EQ(r.error().code, ErrorCode::invalid_argument);
  EXPECT_NE(r.error().message.find("#1"), std::string::npos);
}

TEST(SliceBasic, HeightsByStepAreMidLayerPlanes) {
  const auto zs = heights_by_step(1.0, 0.25);
  ASSERT_EQ(zs.size(), 4u);
  EXPECT_DOUBLE_EQ(zs[0], 0.125);
  EXPECT_DOUBLE_EQ(zs[3], 0.875);
  EXPECT_TRUE(heights_by_step(1.0, 0.0).empty());
}

}  // namespace
}  // namespace lamina
