// build_mesh on damaged soups made in code: every defect found, counted, located, repaired
// where it can be.
#include "mesh_checks.hpp"
#include "mesh_soups.hpp"

#include <lamina/core/mesh.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace lamina {
namespace {

using mesh_test::append;
using mesh_test::box;
using mesh_test::build_checked;
using mesh_test::inverted;
using mesh_test::structure_problem;
using mesh_test::unit_cube;


std::size_t repair_defect_count(const Mesh& m, std::string_view code) {
  const Defect* d = m.find_defect(code);
  return d ? d->count : 0;
}

// ---- welding -----------------------------------------------------------------------------------

TEST(MeshRepair, PerturbedCubeIsWeldedBackTogether) {
  const TriangleSoup s = mesh_test::perturbed(unit_cube());
  const Mesh m = build_checked(s);
  EXPECT_EQ(m.summary.vertices, 8u);
  EXPECT_EQ(m.edges.size(), 18u);
  EXPECT_TRUE(m.summary.watertight);
  EXPECT_TRUE(m.usable());
  EXPECT_NEAR(m.summary.volume_mm3, 1.0, 1e-6);
  const Defect* d = m.find_defect("welded_vertices");
  ASSERT_NE(d, nullptr);
  EXPECT_EQ(d->severity, Severity::repaired);
  // Each corner exists as its exact value plus perturbed copies; every copy is merged.
  EXPECT_GT(d->count, 0u);
  EXPECT_NE(d->message.find("welded"), std::string::npos) << d->message;
  ASSERT_TRUE(d->where.has_value());
}

TEST(MeshRepair, ExactWeldAloneLeavesThePerturbedCubeOpen) {
  MeshParams p;
  p.weld_tolerance_rel = 0.0;
  const Mesh m = build_checked(mesh_test::perturbed(unit_cube()), p);
  EXPECT_GT(m.summary.vertices, 8u);
  EXPECT_GT(m.summary.boundary_edges, 0u);
  EXPECT_FALSE(m.summary.watertight);
  EXPECT_EQ(m.find_defect("welded_vertices"), nullptr);
  EXPECT_FALSE(m.usable());
}

TEST(MeshRepair, CleanCubeReportsNoWeld) {
  EXPECT_EQ(build_checked(unit_cube()).find_defect("welded_vertices"), nullptr);
}

TEST(MeshRepair, ToleranceComesFromTheWholeModelNotASample) {
  // The tolerance is relative to the whole model's box. A lone far triangle (facet 1: a sampling
  // shortcut taking every 2nd facet would miss it) makes the diagonal ~1700, so the tolerance
  // (1e-7 × that) must weld the sphere's corners displaced by 1e-5, which a tolerance sized from
  // the sphere alone (~3.5e-7) would not.
  TriangleSoup sphere = mesh_test::uv_sphere(1.0, 128, 40);
  for (std::size_t c = 1; c < sphere.corners.size(); c += 2) sphere.corners[c] += Eigen::Vector3f(1e-5f, -1e-5f, 1e-5f);
  TriangleSoup s;
  s.corners.assign(sphere.corners.begin(), sphere.corners.begin() + 3);
  mesh_test::add_tri(s, {1000, 1000, 1000}, {1001, 1000, 1000}, {1000, 1001, 1000});  // facet 1
  s.corners.insert(s.corners.end(), sphere.corners.begin() + 3, sphere.corners.end());
  ASSERT_GE(s.triangle_count(), 8192u);
  const Mesh m = build_checked(s);
  EXPECT_EQ(m.summary.boundary_edges, 3u);  // only the lone triangle's
  EXPECT_EQ(m.summary.shells, 2);
  EXPECT_TRUE(m.shell_info[0].closed);
  EXPECT_GT(repair_defect_count(m, "welded_vertices"), 0u);
  EXPECT_EQ(m.summary.vertices, 2u + 128u * 39 + 3);
}

TEST(MeshRepair, MinusZeroIsZeroEvenForTheExactWeld) {
  TriangleSoup s = unit_cube();
  for (std::size_t c = 0; c < s.corners.size(); c += 2)
    for (int a = 0; a < 3; ++a)
      if (s.corners[c][a] == 0.0f) s.corners[c][a] = -0.0f;
  MeshParams p;
  p.weld_tolerance_rel = 0.0;
  const Mesh m = build_checked(s, p);
  EXPECT_EQ(m.summary.vertices, 8u);
  EXPECT_TRUE(m.summary.watertight);
}

TEST(MeshRepair, PointsFartherThanTheToleranceStayApart) {
  // Two cubes 1e-3 apart (tolerance is 1e-7 × diagonal ≈ 3e-7): no weld, two shells.
  const Mesh m = build_checked(append(unit_cube(), box({1.001f, 0, 0}, {2.001f, 1, 1})));
  EXPECT_EQ(m.summary.vertices, 16u);
  EXPECT_EQ(m.summary.shells, 2);
  EXPECT_EQ(m.find_defect("welded_vertices"), nullptr);
}

// ---- winding -----------------------------------------------------------------------------------

TEST(MeshRepair, OneFlippedFacetIsTurnedBack) {
  TriangleSoup s = unit_cube();
  mesh_test::flip_facet(s, 5);
  const Mesh m = build_checked(s);
  const Defect* d = m.find_defect("inconsistent_winding");
  ASSERT_NE(d, nullptr);
  EXPECT_EQ(d->severity, Severity::repaired);
  EXPECT_EQ(d->count, 1u);
  EXPECT_EQ(m.find_defect("inside_out"), nullptr);
  EXPECT_NEAR(m.summary.volume_mm3, 1.0, 1e-12);
  EXPECT_TRUE(m.summary.watertight);
  EXPECT_TRUE(m.usable());
  EXPECT_EQ(m.summary.surfaces, 6);
  EXPECT_LT((m.normals[5] + Eigen::Vector3d::UnitY()).norm(), 1e-15);  // facet 5 is on -y
}

TEST(MeshRepair, MinorityOfFacetsIsFlipped) {
  TriangleSoup s = unit_cube();
  for (std::size_t f : {0u, 1u, 2u, 3u, 4u, 5u, 6u, 7u}) mesh_test::flip_facet(s, f);  // 8 of 12
  const Mesh m = build_checked(s);
  EXPECT_EQ(repair_defect_count(m, "inconsistent_winding"), 4u);
  EXPECT_NEAR(m.summary.volume_mm3, 1.0, 1e-12);
}

TEST(MeshRepair, InsideOutCubeIsTurnedOver) {
  const Mesh m = build_checked(inverted(unit_cube()));
  const Defect* d = m.find_defect("inside_out");
  ASSERT_NE(d, nullptr);
  EXPECT_EQ(d->severity, Severity::repaired);
  EXPECT_EQ(d->count, 1u);
  EXPECT_EQ(m.find_defect("inconsistent_winding"), nullptr);
  EXPECT_NEAR(m.summary.volume_mm3, 1.0, 1e-12);
  EXPECT_LT((m.normals[0] + Eigen::Vector3d::UnitZ()).norm(), 1e-15);  // bottom faces down
  EXPECT_TRUE(m.usable());
}

// ---- shells and cavities -------------------------------------------------------------------------

TEST(MeshRepair, CubeWithCavityKeepsTheCavityNegative) {
  // Outer 3³ outward, inner 1³ cavity wound inward (as a correct file has it).
  const TriangleSoup s = append(box({0, 0, 0}, {3, 3, 3}), inverted(box({1, 1, 1}, {2, 2, 2})));
  const Mesh m = build_checked(s);
  EXPECT_NEAR(m.summary.volume_mm3, 26.0, 1e-12);
  ASSERT_EQ(m.summary.shells, 2);
  EXPECT_NEAR(m.shell_info[0].volume_mm3, 27.0, 1e-12);
  EXPECT_NEAR(m.shell_info[1].volume_mm3, -1.0, 1e-12);
  EXPECT_EQ(m.shell_info[0].depth, 0);
  EXPECT_EQ(m.shell_info[1].depth, 1);
  EXPECT_EQ(m.find_defect("inside_out"), nullptr);
  EXPECT_TRUE(m.summary.watertight);
  const Defect* d = m.find_defect("multiple_shells");
  ASSERT_NE(d, nullptr);
  EXPECT_EQ(d->severity, Severity::info);
  EXPECT_EQ(d->count, 2u);
  // Cavity facets face into the hole: the cavity's bottom (z = 1) faces up.
  EXPECT_LT((m.normals[12] - Eigen::Vector3d::UnitZ()).norm(), 1e-15);
}

TEST(MeshRepair, CavityWoundOutwardIsTurnedInward) {
  const Mesh m = build_checked(append(box({0, 0, 0}, {3, 3, 3}), box({1, 1, 1}, {2, 2, 2})));
  EXPECT_EQ(repair_defect_count(m, "inside_out"), 1u);
  EXPECT_NEAR(m.summary.volume_mm3, 26.0, 1e-12);
  EXPECT_NEAR(m.shell_info[1].volume_mm3, -1.0, 1e-12);
}

TEST(MeshRepair, EverythingInvertedIsTurnedBack) {
  const Mesh m = build_checked(inverted(append(box({0, 0, 0}, {3, 3, 3}), inverted(box({1, 1, 1}, {2, 2, 2})))));
  EXPECT_EQ(repair_defect_count(m, "inside_out"), 2u);
  EXPECT_NEAR(m.summary.volume_mm3, 26.0, 1e-12);
}

TEST(MeshRepair, IslandInsideACavityIsASolidAgain) {
  // Solid 5³, cavity 3³, and a 1³ solid floating in the cavity, all given wound outward.
  const TriangleSoup s =
      append(append(box({0, 0, 0}, {5, 5, 5}), box({1, 1, 1}, {4, 4, 4})), box({2, 2, 2}, {3, 3, 3}));
  const Mesh m = build_checked(s);
  ASSERT_EQ(m.summary.shells, 3);
  EXPECT_EQ(m.shell_info[0].depth, 0);
  EXPECT_EQ(m.shell_info[1].depth, 1);
  EXPECT_EQ(m.shell_info[2].depth, 2);
  EXPECT_NEAR(m.shell_info[2].volume_mm3, 1.0, 1e-12);
  EXPECT_NEAR(m.summary.volume_mm3, 125.0 - 27.0 + 1.0, 1e-12);
  EXPECT_EQ(repair_defect_count(m, "inside_out"), 1u);
}

TEST(MeshRepair, ManyVoidsInABlockAreAllCavities) {
  // A 20 mm block with 10 × 10 × 4 small cubic voids, all given wound outward (wrong).
  TriangleSoup s = box({0, 0, 0}, {20, 20, 20});
  for (int i = 0; i < 10; ++i)
    for (int j = 0; j < 10; ++j)
      for (int k = 0; k < 4; ++k) {
        const Eigen::Vector3f lo(1.0f + 1.8f * static_cast<float>(i), 1.0f + 1.8f * static_cast<float>(j),
                                 2.0f + 4.0f * static_cast<float>(k));
        s = append(s, box(lo, lo + Eigen::Vector3f::Constant(0.5f)));
      }
  const Mesh m = build_checked(s);
  ASSERT_EQ(m.summary.shells, 401);
  EXPECT_EQ(repair_defect_count(m, "inside_out"), 400u);
  EXPECT_NEAR(m.summary.volume_mm3, 8000.0 - 400 * 0.125, 1e-6);
  for (int sh = 1; sh < 401; ++sh) {
    EXPECT_EQ(m.shell_info[static_cast<std::size_t>(sh)].depth, 1);
    EXPECT_LT(m.shell_info[static_cast<std::size_t>(sh)].volume_mm3, 0.0);
  }
  EXPECT_NE(m.find_defect("multiple_shells")->message.find("401 separate shells (1 solid, 400 cavities)"), std::string::npos)
      << m.find_defect("multiple_shells")->message;
}

TEST(MeshRepair, SphericalCavityInASphere) {
  // Curved, finely faceted container: the cavity (given outward) is found inside it.
  const TriangleSoup outer = mesh_test::uv_sphere(10.0, 64, 32), inner = mesh_test::uv_sphere(4.0, 32, 16, {1, 0, 0.5});
  const Mesh m = build_checked(append(outer, inner));
  ASSERT_EQ(m.summary.shells, 2);
  EXPECT_EQ(m.shell_info[1].depth, 1);
  EXPECT_EQ(repair_defect_count(m, "inside_out"), 1u);
  EXPECT_NEAR(m.summary.volume_mm3, mesh_test::soup_volume(outer) - mesh_test::soup_volume(inner), 1e-6);
}

TEST(MeshRepair, OverlappingSolidsAreNotCavities) {
  // Two intersecting boxes, neither inside the other: both stay solids.
  const Mesh m = build_checked(append(box({0, 0, 0}, {2, 2, 2}), box({1, 0.5f, 0.5f}, {3, 1.5f, 1.5f})));
  ASSERT_EQ(m.summary.shells, 2);
  EXPECT_GT(m.shell_info[0].volume_mm3, 0.0);
  EXPECT_GT(m.shell_info[1].volume_mm3, 0.0);
  EXPECT_EQ(m.find_defect("inside_out"), nullptr);
}

TEST(MeshRepair, TwoDisjointCubes) {
  const Mesh m = build_checked(append(unit_cube(), inverted(box({3, 0, 0}, {4, 1, 1}))));
  EXPECT_EQ(m.summary.shells, 2);
  EXPECT_EQ(repair_defect_count(m, "multiple_shells"), 2u);
  EXPECT_EQ(repair_defect_count(m, "inside_out"), 1u);
  EXPECT_NEAR(m.summary.volume_mm3, 2.0, 1e-12);
  EXPECT_TRUE(m.summary.watertight);
  EXPECT_TRUE(m.usable());
  for (std::size_t f = 0; f < 24; ++f) EXPECT_EQ(m.shell_id[f], f < 12 ? 0 : 1);
  EXPECT_EQ(m.summary.surfaces, 12);
}

// ---- open and non-manifold -----------------------------------------------------------------------

TEST(MeshRepair, MissingFacetLeavesOpenEdges) {
  const Mesh m = build_checked(mesh_test::without_facet(unit_cube(), 3));  // half of the +z face
  EXPECT_EQ(m.summary.boundary_edges, 3u);
  EXPECT_FALSE(m.summary.watertight);
  EXPECT_FALSE(m.usable());
  const Defect* d = m.find_defect("open_edges");
  ASSERT_NE(d, nullptr);
  EXPECT_EQ(d->severity, Severity::error);
  EXPECT_EQ(d->count, 3u);
  EXPECT_NE(d->message.find("3 open (boundary) edges in 1 place"), std::string::npos) << d->message;
  ASSERT_TRUE(d->where.has_value());
  EXPECT_NEAR(d->where->z(), 1.0, 1e-12);  // the hole is in the top face
  EXPECT_FALSE(m.shell_info[0].closed);
}

TEST(MeshRepair, TwoHolesAreTwoPlaces) {
  const Mesh m = build_checked(mesh_test::without_facet(mesh_test::without_facet(unit_cube(), 3), 0));  // top and bottom
  const Defect* d = m.find_defect("open_edges");
  ASSERT_NE(d, nullptr);
  EXPECT_EQ(d->count, 6u);
  EXPECT_NE(d->message.find("in 2 places"), std::string::npos) << d->message;
}

TEST(MeshRepair, CubesSharingAnEdgeAreNonManifoldAndTwoShells) {
  // The second cube touches the first along the vertical edge x = 1, y = 1; it is inside out.
  const Mesh m = build_checked(append(unit_cube(), inverted(box({1, 1, 0}, {2, 2, 1}))));
  EXPECT_EQ(m.summary.nonmanifold_edges, 1u);
  EXPECT_EQ(m.summary.boundary_edges, 0u);
  EXPECT_EQ(m.summary.shells, 2);  // the non-manifold edge does not join them
  EXPECT_TRUE(m.shell_info[0].closed);
  EXPECT_TRUE(m.shell_info[1].closed);
  EXPECT_EQ(repair_defect_count(m, "inside_out"), 1u);
  EXPECT_EQ(m.find_defect("inconsistent_winding"), nullptr);
  EXPECT_NEAR(m.summary.volume_mm3, 2.0, 1e-12);
  EXPECT_FALSE(m.summary.watertight);
  EXPECT_TRUE(m.usable());
  const Defect* d = m.find_defect("nonmanifold_edges");
  ASSERT_NE(d, nullptr);
  EXPECT_EQ(d->severity, Severity::warning);
  ASSERT_TRUE(d->where.has_value());
  EXPECT_LT((*d->where - Eigen::Vector3d(1, 1, 0.5)).norm(), 1e-12);
  EXPECT_EQ(m.summary.vertices, 14u);
}

// ---- degenerate and non-finite ---------------------------------------------------------------

TEST(MeshRepair, DegenerateFacetsAreDropped) {
  TriangleSoup s = unit_cube();
  mesh_test::add_tri(s, {0, 0, 0}, {0, 0, 0}, {1, 0, 0});      // repeated corner
  mesh_test::add_tri(s, {0, 0, 0}, {0.5f, 0, 0}, {1, 0, 0});   // collinear: zero area
  const Mesh m = build_checked(s);
  EXPECT_EQ(m.summary.triangles_read, 14u);
  EXPECT_EQ(m.summary.triangles, 12u);
  EXPECT_EQ(m.summary.vertices, 8u);  // (0.5, 0, 0) was only used by a dropped facet
  EXPECT_TRUE(m.summary.watertight);
  const Defect* d = m.find_defect("degenerate_facets");
  ASSERT_NE(d, nullptr);
  EXPECT_EQ(d->severity, Severity::repaired);
  EXPECT_EQ(d->count, 2u);
  ASSERT_TRUE(d->where.has_value());
  EXPECT_LT((*d->where - Eigen::Vector3d(1.0 / 3, 0, 0)).norm(), 1e-12);
}

TEST(MeshRepair, FacetCollapsedByTheWeldIsDegenerate) {
  TriangleSoup s = unit_cube();
  mesh_test::add_tri(s, {0, 0, 0}, {1e-9f, 0, 0}, {1, 1, 1});  // two corners weld into one
  const Mesh m = build_checked(s);
  EXPECT_EQ(repair_defect_count(m, "degenerate_facets"), 1u);
  EXPECT_EQ(m.summary.triangles, 12u);
}

TEST(MeshRepair, NanCornerDropsItsFacet) {
  TriangleSoup s = unit_cube();
  mesh_test::add_tri(s, {0, 0, 0}, {std::numeric_limits<float>::quiet_NaN(), 0, 0}, {1, 1, 1});
  mesh_test::add_tri(s, {0, 0, 0}, {1, std::numeric_limits<float>::infinity(), 0}, {1, 1, 1});
  const Mesh m = build_checked(s);
  const Defect* d = m.find_defect("nan_coordinates");
  ASSERT_NE(d, nullptr);
  EXPECT_EQ(d->severity, Severity::repaired);
  EXPECT_EQ(d->count, 2u);
  EXPECT_NE(d->message.find("facet 12"), std::string::npos) << d->message;
  EXPECT_EQ(m.summary.triangles, 12u);
  EXPECT_EQ(m.summary.vertices, 8u);
  EXPECT_TRUE(m.summary.watertight);
  EXPECT_TRUE(m.usable());
  EXPECT_EQ(m.summary.bbox_max_mm, Eigen::Vector3d(1, 1, 1));  // the NaN facet's other corners do not count
}

TEST(MeshRepair, EmptySoupIsAnError) {
  const auto r = build_mesh(TriangleSoup{}, MeshParams{});
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::empty_mesh);
}

TEST(MeshRepair, OnlyNanFacetsIsAnError) {
  TriangleSoup s;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  mesh_test::add_tri(s, {nan, 0, 0}, {1, 0, 0}, {0, 1, 0});
  const auto r = build_mesh(s, MeshParams{});
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::empty_mesh);
  EXPECT_NE(r.error().message.find("NaN"), std::string::npos) << r.error().message;
}

TEST(MeshRepair, OnlyDegenerateFacetsIsAnError) {
  TriangleSoup s;
  mesh_test::add_tri(s, {0, 0, 0}, {1, 0, 0}, {2, 0, 0});
  const auto r = build_mesh(s, MeshParams{});
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::empty_mesh);
}

TEST(MeshRepair, SingleTriangleIsOpen) {
  TriangleSoup s;
  mesh_test::add_tri(s, {0, 0, 0}, {1, 0, 0}, {0, 1, 0});
  const Mesh m = build_checked(s);
  EXPECT_EQ(m.summary.boundary_edges, 3u);
  EXPECT_FALSE(m.usable());
  EXPECT_EQ(m.find_defect("inside_out"), nullptr);  // a flat patch has no inside
  EXPECT_LT((m.normals[0] - Eigen::Vector3d::UnitZ()).norm(), 1e-15);
}

}  // namespace
}  // namespace lamina
