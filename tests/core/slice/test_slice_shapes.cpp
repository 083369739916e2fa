// Faceted analytic solids whose sections are known exactly (tests/support/shapes.hpp): the slicer
// must reproduce them within 0.05 %, and the areas must not change when the model is rotated
// arbitrarily and sliced along the rotated build direction (seeded property test).
#include "lamina/core/mesh.hpp"
#include "lamina/core/slice.hpp"
#include "mesh_checks.hpp"
#include "shapes.hpp"

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <random>

namespace lamina {
namespace {

constexpr double kRel = 5e-4;  // 0.05 %

std::vector<Slice> slice_at(const Mesh& mesh, const std::vector<double>& zs) {
  auto s = slice_mesh(mesh, zs, SliceParams{});
  EXPECT_TRUE(s.has_value());
  return s ? std::move(*s) : std::vector<Slice>{};
}

std::vector<double> random_heights(std::mt19937& rng, double lo, double hi, int n) {
  std::uniform_real_distribution<double> u(lo, hi);
  std::vector<double> zs;
  for (int i = 0; i < n; ++i) zs.push_back(u(rng));
  return zs;
}

TEST(SliceShapes, SphereSectionsMatchTheFacetedSolid) {
  const double r = 50.0;
  const int seg = 96, rings = 48;
  const Mesh mesh = mesh_test::build_checked(test::uv_sphere(r, seg, rings));
  std::mt19937 rng(7);
  const auto zs = random_heights(rng, 0.01, 2 * r - 0.01, 40);
  const auto slices = slice_at(mesh, zs);
  for (std::size_t i = 0; i < zs.size(); ++i) {
    const double expected = test::uv_sphere_section_area(r, seg, rings, zs[i] - r);
    ASSERT_EQ(slices[i].loops.size(), 1u) << "z=" << zs[i];
    EXPECT_EQ(slices[i].outer_count(), 1);
    EXPECT_NEAR(slices[i].net_area_mm2(), expected, kRel * expected) << "z=" << zs[i];
  }
}

TEST(SliceShapes, TubeHasOneOuterAndOneNestedHole) {
  const double R = 30, r = 12, h = 40;
  const int seg = 64;
  const Mesh mesh = mesh_test::build_checked(test::tube(R, r, h, seg));
  std::mt19937 rng(11);
  const auto zs = random_heights(rng, 0.1, h - 0.1, 20);
  const auto slices = slice_at(mesh, zs);
  for (std::size_t i = 0; i < zs.size(); ++i) {
    const Slice& s = slices[i];
    ASSERT_EQ(s.loops.size(), 2u);
    EXPECT_EQ(s.outer_count(), 1);
    EXPECT_EQ(s.hole_count(), 1);
    const std::size_t hole = s.loops[0].is_hole() ? 0 : 1;
    EXPECT_EQ(s.loops[hole].parent, static_cast<int>(1 - hole));
    EXPECT_EQ(s.loops[hole].depth, 1);
    const double expected = test::tube_section_area(R, r, h, seg, zs[i]);
    EXPECT_NEAR(s.net_area_mm2(), expected, kRel * expected);
    // Hole vectors run clockwise: still z × n with n pointing out of the material (into the hole).
    for (std::size_t k = 0; k < s.loops[hole].size(); ++k) {
      const ContourVector v = s.vector(mesh, hole, k);
      const Eigen::Vector2d d = (v.end_mm - v.start_mm).normalized();
      EXPECT_NEAR(d.x(), -v.normal.y(), 1e-6);
      EXPECT_NEAR(d.y(), v.normal.x(), 1e-6);
      EXPECT_LT(v.start_mm.dot(v.normal.head<2>()), 0.0) << "hole normals point to the axis";
    }
  }
}

TEST(SliceShapes, TorusSectionsMatchTheFacetedSolid) {
  const double R = 30, r = 10;
  const int maj = 72, minr = 36;
  const Mesh mesh = mesh_test::build_checked(test::torus(R, r, maj, minr));
  const double zmin = test::torus_z_min(r, minr), zmax = test::torus_z_max(r, minr);
  std::mt19937 rng(13);
  const auto zs = random_heights(rng, 0.05, zmax - zmin - 0.05, 30);
  const auto slices = slice_at(mesh, zs);
  for (std::size_t i = 0; i < zs.size(); ++i) {
    const double expected = test::torus_section_area(R, r, maj, minr, zs[i] + zmin);
    EXPECT_EQ(slices[i].outer_count(), 1);
    EXPECT_EQ(slices[i].hole_count(), 1);
    EXPECT_NEAR(slices[i].net_area_mm2(), expected, kRel * expected) << "z=" << zs[i];
  }
}

// Rotate the model by a random rotation Q and build along Q·ẑ: the build frame undoes Q up to a
// turn about z, which leaves every section area unchanged.
TEST(SliceShapes, AreasAreInvariantUnderRandomRotations) {
  const TriangleSoup torus = test::torus(30, 10, 72, 36);
  const TriangleSoup tube = test::tube(25, 8, 30, 48);
  std::mt19937 rng(2026);
  std::normal_distribution<double> g;
  for (const TriangleSoup* shape : {&torus, &tube}) {
    const Mesh reference = mesh_test::build_checked(*shape);
    const double h = reference.summary.bbox_max_mm.z();
    const std::vector<double> zs{0.13 * h, 0.37 * h, 0.5 * h, 0.71 * h, 0.93 * h};
    const auto want = slice_at(reference, zs);
    for (int trial = 0; trial < 8; ++trial) {
      const Eigen::Quaterniond q = Eigen::Quaterniond(g(rng), g(rng), g(rng), g(rng)).normalized();
      TriangleSoup rotated = *shape;
      const Eigen::Vector3d shift(g(rng) * 100, g(rng) * 100, g(rng) * 100);
      for (auto& c : rotated.corners) c = (q * c.cast<double>() + shift).cast<float>();
      MeshParams p;
      p.direction = q * Eigen::Vector3d::UnitZ();
      const Mesh mesh = mesh_test::build_checked(rotated, p);
      EXPECT_NEAR(mesh.summary.bbox_max_mm.z(), h, 1e-4 * h);
      const auto got = slice_at(mesh, zs);
      for (std::size_t i = 0; i < zs.size(); ++i) {
        SCOPED_TRACE(::testing::Message() << "trial " << trial << " z=" << zs[i]);
        EXPECT_EQ(got[i].outer_count(), want[i].outer_count());
        EXPECT_EQ(got[i].hole_count(), want[i].hole_count());
        EXPECT_NEAR(got[i].net_area_mm2(), want[i].net_area_mm2(), 1e-4 * want[i].net_area_mm2());
      }
    }
  }
}

}  // namespace
}  // namespace lamina
