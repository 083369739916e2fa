// build_mesh with a B-rep's data (as the STEP reader gives it, made here without OpenCASCADE so
// the sanitizer pass checks it too): faces become the surfaces whatever the dihedral angle, the
// corners' normals follow their vertices when orientation turns a facet round, and the analytic
// surfaces give exact normals in the build frame.
#include <gtest/gtest.h>

#include "lamina/core/mesh.hpp"
#include "lamina/core/surface_normal.hpp"

#include <cmath>
#include <numbers>

namespace lamina {
namespace {

// An n-sided prism around the z axis (radius r, height h) as a B-rep would tessellate a cylinder:
// face 0 the side (a cylinder), face 1 the bottom, face 2 the top (planes). With `flip_one`, one
// side triangle is stored wound the wrong way (its corner normals stay with its vertices).
TriangleSoup prism(int n, double r, double h, bool flip_one) {
  TriangleSoup s;
  BrepData& b = s.brep.emplace();
  b.faces = {BrepFace{SurfaceKind::cylinder, 0, Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ(), r},
             BrepFace{SurfaceKind::plane, 0, Eigen::Vector3d::Zero(), -Eigen::Vector3d::UnitZ()},
             BrepFace{SurfaceKind::plane, 0, Eigen::Vector3d(0, 0, h), Eigen::Vector3d::UnitZ()}};
  b.solids = {BrepSolid{"prism", 3, 0}};
  auto at = [&](int i, double z) {
    const double a = 2 * std::numbers::pi * i / n;
    return Eigen::Vector3f(static_cast<float>(r * std::cos(a)), static_cast<float>(r * std::sin(a)), static_cast<float>(z));
  };
  // Not the cylinder's normal (the test of the corners' order needs each vertex's to differ; the
  // analytic face gives the exact one anyway).
  auto radial = [&](const Eigen::Vector3f& p) { return Eigen::Vector3f(p.x(), p.y(), 0.3f * p.z()).normalized(); };
  auto add = [&](std::array<Eigen::Vector3f, 3> c, std::int32_t face, bool side) {
    for (const auto& p : c) {
      s.corners.push_back(p);
      b.corner_normals.push_back(side ? radial(p) : Eigen::Vector3f(b.faces[static_cast<std::size_t>(face)].axis.cast<float>()));
    }
    b.triangle_face.push_back(face);
  };
  for (int i = 0; i < n; ++i) {
    const auto p0 = at(i, 0), p1 = at(i + 1, 0), q0 = at(i, h), q1 = at(i + 1, h);
    if (flip_one && i == 0) add({p0, q1, p1}, 0, true);  // inward: orientation turns it round
    else add({p0, p1, q1}, 0, true);
    add({p0, q1, q0}, 0, true);
    add({Eigen::Vector3f(0, 0, 0), p1, p0}, 1, false);
    add({Eigen::Vector3f(0, 0, static_cast<float>(h)), q0, q1}, 2, false);
  }
  return s;
}

TEST(MeshBrep, TheFacesAreTheSurfacesWhateverTheDihedralAngle) {
  // 64 sides: 5.6° between neighbouring side facets, one surface by the dihedral rule too; but
  // the caps meet the side at 90° and the B-rep says three faces.
  auto m = build_mesh(prism(64, 10, 5, false), MeshParams{});
  ASSERT_TRUE(m) << m.error().message;
  EXPECT_EQ(m->summary.surfaces, 3);
  ASSERT_EQ(m->brep_faces.size(), 3u);
  EXPECT_TRUE(m->summary.watertight);
  for (std::size_t f = 0; f < m->faces.size(); ++f) EXPECT_LE(m->surface_id[f], 2);
  // Without the B-rep, an 11-sided prism's sides are 32.7° apart, above the 30° rule: each its
  // own surface. The dihedral rule cannot know they are one cylinder.
  TriangleSoup mesh_only = prism(11, 10, 5, false);
  mesh_only.brep.reset();
  EXPECT_GT(build_mesh(mesh_only, MeshParams{})->summary.surfaces, 3);
}

TEST(MeshBrep, CornerNormalsFollowTheirVerticesWhenAFacetIsTurnedRound) {
  auto m = build_mesh(prism(24, 10, 5, true), MeshParams{});
  ASSERT_TRUE(m) << m.error().message;
  EXPECT_NE(m->find_defect("inconsistent_winding"), nullptr) << "the flipped triangle was repaired";
  ASSERT_EQ(m->corner_normals.size(), m->faces.size());
  for (std::size_t f = 0; f < m->faces.size(); ++f) {
    if (m->surface_id[f] != 0) continue;
    for (std::size_t k = 0; k < 3; ++k) {
      const Eigen::Vector3d p = m->vertices[static_cast<std::size_t>(m->faces[f][k])];
      const Eigen::Vector3d expected = Eigen::Vector3d(p.x(), p.y(), 0.3 * p.z()).normalized();
      EXPECT_LT((m->corner_normals[f][k].cast<double>() - expected).norm(), 1e-6) << "facet " << f << " corner " << k;
    }
  }
}

TEST(MeshBrep, ACylindersNormalIsExactInTheBuildFrameAndAFacetsIsAChords) {
  MeshParams along_x;
  along_x.axis = BuildAxis::x;  // the file's x becomes the build +Z: the cylinder lies down
  auto m = build_mesh(prism(16, 10, 5, false), along_x);
  ASSERT_TRUE(m) << m.error().message;
  const BrepFace& side = m->brep_faces[0];
  EXPECT_NEAR(std::abs(side.axis.dot(Eigen::Vector3d::UnitZ())), 0, 1e-12) << "the axis turned with the part";
  double worst_exact = 0, worst_facet = 0;
  for (std::size_t f = 0; f < m->faces.size(); ++f) {
    if (m->surface_id[f] != 0) continue;
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    for (auto v : m->faces[f]) c += m->vertices[static_cast<std::size_t>(v)] / 3;
    const Eigen::Vector3d d = c - side.origin, truth = (d - d.dot(side.axis) * side.axis).normalized();
    worst_exact = std::max(worst_exact, (surface_normal_at(*m, static_cast<std::int32_t>(f), c) - truth).norm());
    worst_facet = std::max(worst_facet, (m->normals[f] - truth).norm());
  }
  EXPECT_LT(worst_exact, 1e-9);
  EXPECT_GT(worst_facet, 0.05) << "16 sides: a facet's normal is up to 11° off at its corners' half-way";
}

TEST(MeshBrep, AMeshHasNoneAndDataThatDoesNotMatchItsTrianglesIsRefused) {
  TriangleSoup soup = prism(8, 10, 5, false);
  soup.brep->triangle_face.pop_back();
  auto m = build_mesh(soup, MeshParams{});
  ASSERT_FALSE(m);
  EXPECT_EQ(m.error().code, ErrorCode::invalid_argument);
  soup.brep.reset();
  auto plain = build_mesh(soup, MeshParams{});
  ASSERT_TRUE(plain);
  EXPECT_TRUE(plain->corner_normals.empty());
  EXPECT_EQ(surface_normal_at(*plain, 0, Eigen::Vector3d::Zero()), plain->normals[0]);
}

}  // namespace
}  // namespace lamina
