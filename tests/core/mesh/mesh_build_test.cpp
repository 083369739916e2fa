// build_mesh on clean shapes made in code: counts, topology, frame, surfaces.
#include "mesh_checks.hpp"
#include "mesh_soups.hpp"

#include <lamina/core/mesh.hpp>

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <cmath>
#include <numbers>
#include <set>

namespace lamina {
namespace {

using mesh_test::box;
using mesh_test::build_checked;
using mesh_test::structure_problem;
using mesh_test::unit_cube;


TEST(BuildMesh, UnitCubeCountsAndVolume) {
  const Mesh m = build_checked(unit_cube());
  EXPECT_EQ(m.summary.triangles_read, 12u);
  EXPECT_EQ(m.summary.triangles, 12u);
  EXPECT_EQ(m.summary.vertices, 8u);
  EXPECT_EQ(m.edges.size(), 18u);  // 12 cube edges + 6 face diagonals
  EXPECT_TRUE(m.summary.watertight);
  EXPECT_NEAR(m.summary.volume_mm3, 1.0, 1e-12);
  EXPECT_EQ(m.summary.shells, 1);
  EXPECT_EQ(m.summary.surfaces, 6);  // the diagonals are flat (0°), the cube edges sharp (90°)
  EXPECT_EQ(m.summary.boundary_edges, 0u);
  EXPECT_EQ(m.summary.nonmanifold_edges, 0u);
  EXPECT_TRUE(m.defects.empty()) << m.defects.front().message;
  EXPECT_TRUE(m.usable());
  for (const Edge& e : m.edges) EXPECT_EQ(e.face_count, 2);
  ASSERT_EQ(m.shell_info.size(), 1u);
  EXPECT_TRUE(m.shell_info[0].closed);
  EXPECT_EQ(m.shell_info[0].depth, 0);
  EXPECT_EQ(m.summary.bbox_min_mm, Eigen::Vector3d(0, 0, 0));
  EXPECT_EQ(m.summary.bbox_max_mm, Eigen::Vector3d(1, 1, 1));
}

TEST(BuildMesh, CubeSurfacesAreTheSixFacesWithOutwardNormals) {
  const Mesh m = build_checked(unit_cube());
  // Facets 2k and 2k+1 form face k of the soup; each face is one surface, ids by seed order.
  for (int k = 0; k < 6; ++k) {
    EXPECT_EQ(m.surface_id[static_cast<std::size_t>(2 * k)], k);
    EXPECT_EQ(m.surface_id[static_cast<std::size_t>(2 * k + 1)], k);
  }
  const Eigen::Vector3d expected[6] = {-Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitZ(),  -Eigen::Vector3d::UnitY(),
                                       Eigen::Vector3d::UnitY(),  -Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitX()};
  for (std::size_t f = 0; f < 12; ++f) EXPECT_LT((m.normals[f] - expected[f / 2]).norm(), 1e-15) << f;
}

TEST(BuildMesh, SharpAngleAboveNinetyDegreesMergesTheWholeCube) {
  MeshParams p;
  p.sharp_angle_rad = 91.0 * std::numbers::pi / 180.0;
  EXPECT_EQ(build_checked(unit_cube(), p).summary.surfaces, 1);
  p.sharp_angle_rad = 89.0 * std::numbers::pi / 180.0;
  EXPECT_EQ(build_checked(unit_cube(), p).summary.surfaces, 6);
}

TEST(BuildMesh, LowestPointMovesToZeroAndXYStay) {
  const Mesh m = build_checked(box({5, 6, 7}, {6, 8, 10}));
  EXPECT_EQ(m.summary.bbox_min_mm, Eigen::Vector3d(5, 6, 0));
  EXPECT_EQ(m.summary.bbox_max_mm, Eigen::Vector3d(6, 8, 3));
  EXPECT_NEAR(m.summary.volume_mm3, 6.0, 1e-12);
}

TEST(BuildMesh, BuildAxisXPutsModelXUp) {
  MeshParams p;
  p.axis = BuildAxis::x;
  const Mesh m = build_checked(box({5, 6, 7}, {6, 8, 10}), p);  // 1 × 2 × 3
  // (x, y, z) → (y, z, x): heights come from x.
  EXPECT_EQ(m.summary.bbox_min_mm, Eigen::Vector3d(6, 7, 0));
  EXPECT_EQ(m.summary.bbox_max_mm, Eigen::Vector3d(8, 10, 1));
  EXPECT_NEAR(m.summary.volume_mm3, 6.0, 1e-12);  // a proper rotation keeps the winding
  EXPECT_TRUE(m.defects.empty());
}

TEST(BuildMesh, BuildAxisYPutsModelYUp) {
  MeshParams p;
  p.axis = BuildAxis::y;
  const Mesh m = build_checked(box({5, 6, 7}, {6, 8, 10}), p);
  // (x, y, z) → (z, x, y).
  EXPECT_EQ(m.summary.bbox_min_mm, Eigen::Vector3d(7, 5, 0));
  EXPECT_EQ(m.summary.bbox_max_mm, Eigen::Vector3d(10, 6, 2));
  EXPECT_NEAR(m.summary.volume_mm3, 6.0, 1e-12);
  EXPECT_TRUE(m.defects.empty());
}

TEST(BuildMesh, InchScale) {
  MeshParams p;
  p.scale_to_mm = 25.4;
  const Mesh m = build_checked(box({0, 0, 0}, {1, 2, 3}), p);
  EXPECT_NEAR(m.summary.bbox_max_mm.z(), 76.2, 1e-12);
  EXPECT_NEAR(m.summary.bbox_max_mm.x(), 25.4, 1e-12);
  EXPECT_NEAR(m.summary.volume_mm3, 6.0 * 25.4 * 25.4 * 25.4, 1e-9);
}

TEST(BuildMesh, UvSphereIsOneSmoothSurface) {
  const TriangleSoup s = mesh_test::uv_sphere(10.0, 48, 24);
  const Mesh m = build_checked(s);
  EXPECT_EQ(m.summary.triangles, 48u * 2 + 48u * 22 * 2);
  EXPECT_EQ(m.summary.vertices, 2u + 48u * 23);
  EXPECT_EQ(m.edges.size(), 3 * m.summary.triangles / 2);
  EXPECT_TRUE(m.summary.watertight);
  EXPECT_EQ(m.summary.shells, 1);
  EXPECT_EQ(m.summary.surfaces, 1);
  EXPECT_TRUE(m.defects.empty());
  // Euler: V − E + F = 2 for a sphere.
  EXPECT_EQ(static_cast<long>(m.summary.vertices) - static_cast<long>(m.edges.size()) + static_cast<long>(m.summary.triangles), 2);
  EXPECT_NEAR(m.summary.volume_mm3, mesh_test::soup_volume(s), 1e-9 * mesh_test::soup_volume(s));
  EXPECT_NEAR(m.summary.volume_mm3, 4.0 / 3.0 * std::numbers::pi * 1000.0, 0.01 * 4188.8);
  EXPECT_NEAR(m.summary.bbox_max_mm.z(), 20.0, 1e-5);
  // Outward: every normal points away from the centre (now at z = 10).
  for (std::size_t f = 0; f < m.faces.size(); ++f) {
    const Eigen::Vector3d c = (m.vertices[static_cast<std::size_t>(m.faces[f][0])] +
                               m.vertices[static_cast<std::size_t>(m.faces[f][1])] +
                               m.vertices[static_cast<std::size_t>(m.faces[f][2])]) / 3.0;
    ASSERT_GT(m.normals[f].dot(c - Eigen::Vector3d(0, 0, 10)), 0.0) << f;
  }
}

TEST(BuildMesh, SphereSplitsIntoManySurfacesWithATinyThreshold) {
  MeshParams p;
  p.sharp_angle_rad = 1.0 * std::numbers::pi / 180.0;  // adjacent quads are 7.5° apart
  const Mesh m = build_checked(mesh_test::uv_sphere(10.0, 48, 24), p);
  // The two halves of each quad (coplanar) stay together: 48·22 quads. Each pole fan is one
  // surface: its neighbours are only 7.5° · sin(3.75°) ≈ 0.5° apart.
  EXPECT_EQ(m.summary.surfaces, 48 * 22 + 2);
}

TEST(BuildMesh, CylinderHasSideAndTwoCaps) {
  const TriangleSoup s = mesh_test::cylinder(5.0, 20.0, 32);
  const Mesh m = build_checked(s);
  EXPECT_TRUE(m.summary.watertight);
  EXPECT_EQ(m.summary.surfaces, 3);
  EXPECT_NEAR(m.summary.volume_mm3, mesh_test::soup_volume(s), 1e-9 * mesh_test::soup_volume(s));
  std::set<std::int32_t> side, caps;
  for (std::size_t f = 0; f < m.faces.size(); ++f) {
    if (std::abs(m.normals[f].z()) > 0.999)
      caps.insert(m.surface_id[f]);
    else
      side.insert(m.surface_id[f]);
  }
  EXPECT_EQ(side.size(), 1u);
  EXPECT_EQ(caps.size(), 2u);
  EXPECT_EQ(side.count(*caps.begin()), 0u);
}

TEST(BuildMesh, TwelveGonCylinderSideStaysOneSurfaceAtExactlyThirtyDegrees) {
  // Neighbouring side facets of a 12-gon are exactly 30° apart: "≤ threshold" joins them.
  EXPECT_EQ(build_checked(mesh_test::cylinder(5.0, 20.0, 12)).summary.surfaces, 3);
  EXPECT_EQ(build_checked(mesh_test::cylinder(5.0, 20.0, 11)).summary.surfaces, 2 + 11);
}

TEST(BuildMesh, SameInputSameOutput) {
  const TriangleSoup s = mesh_test::append(mesh_test::uv_sphere(3.0, 16, 8), mesh_test::perturbed(unit_cube()));
  const Mesh a = build_checked(s), b = build_checked(s);
  EXPECT_EQ(a.vertices, b.vertices);
  EXPECT_EQ(a.faces, b.faces);
  EXPECT_EQ(a.surface_id, b.surface_id);
  EXPECT_EQ(a.shell_id, b.shell_id);
  EXPECT_EQ(a.edge_faces, b.edge_faces);
  EXPECT_EQ(a.summary.volume_mm3, b.summary.volume_mm3);
}

TEST(BuildMesh, ThreadCountDoesNotChangeTheResult) {
  // Big enough (81408 facets) for the chunked edge sort to split.
  const TriangleSoup s = mesh_test::append(mesh_test::perturbed(mesh_test::uv_sphere(30.0, 256, 160)),
                                           mesh_test::inverted(box({100, 0, 0}, {101, 1, 1})));
  Mesh serial, parallel;
  tbb::task_arena one(1);
  one.execute([&] { serial = build_checked(s); });
  parallel = build_checked(s);
  EXPECT_EQ(serial.summary.triangles, 2u * 256 * 159 + 12);
  EXPECT_TRUE(serial.summary.watertight);
  EXPECT_EQ(serial.summary.shells, 2);
  EXPECT_EQ(serial.summary.surfaces, 1 + 6);
  EXPECT_NE(serial.find_defect("welded_vertices"), nullptr);
  EXPECT_EQ(serial.vertices, parallel.vertices);
  EXPECT_EQ(serial.faces, parallel.faces);
  EXPECT_EQ(serial.normals, parallel.normals);
  EXPECT_EQ(serial.surface_id, parallel.surface_id);
  EXPECT_EQ(serial.shell_id, parallel.shell_id);
  EXPECT_EQ(serial.edge_faces, parallel.edge_faces);
  EXPECT_EQ(serial.face_edges, parallel.face_edges);
  ASSERT_EQ(serial.edges.size(), parallel.edges.size());
  for (std::size_t e = 0; e < serial.edges.size(); ++e) {
    ASSERT_EQ(serial.edges[e].v0, parallel.edges[e].v0);
    ASSERT_EQ(serial.edges[e].v1, parallel.edges[e].v1);
    ASSERT_EQ(serial.edges[e].face_begin, parallel.edges[e].face_begin);
    ASSERT_EQ(serial.edges[e].face_count, parallel.edges[e].face_count);
  }
  EXPECT_EQ(serial.summary.volume_mm3, parallel.summary.volume_mm3);
  ASSERT_EQ(serial.defects.size(), parallel.defects.size());
  for (std::size_t i = 0; i < serial.defects.size(); ++i) EXPECT_EQ(serial.defects[i].message, parallel.defects[i].message);
}

TEST(BuildMesh, InvalidParametersAreRejected) {
  MeshParams p;
  p.scale_to_mm = 0.0;
  auto r = build_mesh(unit_cube(), p);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::invalid_argument);
  p = MeshParams{};
  p.weld_tolerance_rel = std::nan("");
  r = build_mesh(unit_cube(), p);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::invalid_argument);
}

TEST(BuildMesh, SeverityNames) {
  EXPECT_STREQ(severity_name(Severity::info), "info");
  EXPECT_STREQ(severity_name(Severity::repaired), "repaired");
  EXPECT_STREQ(severity_name(Severity::warning), "warning");
  EXPECT_STREQ(severity_name(Severity::error), "error");
}

// Two tessellations of one model (a B-rep planned at one chord, measured against a finer one)
// share a frame: each is lowered by its own lowest vertex, so the finer one is moved by the
// difference. A cylinder on its side: 7 segments reach down to 0.901 r, 6 to r; both have their
// highest vertex at x = r.
TEST(MeshFrame, AnotherTessellationLandsInTheFirstsFrame) {
  MeshParams p;
  p.axis = BuildAxis::x;
  auto coarse = build_mesh(mesh_test::cylinder(10, 30, 7), p);
  auto fine = build_mesh(mesh_test::cylinder(10, 30, 6), p);
  ASSERT_TRUE(coarse && fine);
  EXPECT_NEAR(fine->summary.lowered_mm - coarse->summary.lowered_mm, -10 * (1 - std::cos(std::numbers::pi / 7)), 1e-5);
  const Mesh moved = in_frame_of(*fine, *coarse);
  EXPECT_NEAR(moved.summary.bbox_max_mm.z(), coarse->summary.bbox_max_mm.z(), 1e-5) << "the shared top vertex";
  double lowest = 0, highest = 0;
  for (const Eigen::Vector3d& v : moved.vertices) lowest = std::min(lowest, v.z()), highest = std::max(highest, v.z());
  EXPECT_NEAR(highest, coarse->summary.bbox_max_mm.z(), 1e-5);
  EXPECT_NEAR(lowest, moved.summary.bbox_min_mm.z(), 1e-12);
  EXPECT_LT(lowest, -0.9) << "the finer one reaches below the frame's zero";
  EXPECT_EQ(moved.summary.lowered_mm, coarse->summary.lowered_mm);
}

}  // namespace
}  // namespace lamina
