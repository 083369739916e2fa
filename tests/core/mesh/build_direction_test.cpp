// Any build direction: the model is turned so that the direction points up (+Z).
#include "lamina/core/mesh.hpp"
#include "mesh_soups.hpp"

#include <gtest/gtest.h>

namespace lamina {
namespace {

TriangleSoup slab() {  // 10 x 20 x 30 box as two triangles per face
  TriangleSoup s;
  const Eigen::Vector3f lo(0, 0, 0), hi(10, 20, 30);
  auto v = [&](int c) {
    return Eigen::Vector3f(c & 4 ? hi.x() : lo.x(), c & 2 ? hi.y() : lo.y(), c & 1 ? hi.z() : lo.z());
  };
  const int tris[12][3] = {{0, 2, 6}, {0, 6, 4}, {1, 5, 7}, {1, 7, 3}, {0, 4, 5}, {0, 5, 1},
                           {2, 3, 7}, {2, 7, 6}, {0, 1, 3}, {0, 3, 2}, {4, 6, 7}, {4, 7, 5}};
  for (const auto& t : tris)
    for (int c : t) s.corners.push_back(v(c));
  return s;
}

double height(const Mesh& m) { return m.summary.bbox_max_mm.z() - m.summary.bbox_min_mm.z(); }

TEST(BuildDirection, DirectionVectorTurnsThatDirectionUp) {
  MeshParams p;
  p.direction = Eigen::Vector3d(3, 0, 0);  // need not be unit
  auto m = build_mesh(slab(), p);
  ASSERT_TRUE(m.has_value());
  EXPECT_NEAR(height(*m), 10.0, 1e-9);
  EXPECT_NEAR(m->summary.volume_mm3, 6000.0, 1e-6) << "a rotation keeps volume and winding";

  p.direction = Eigen::Vector3d(0, -1, 0);  // building downwards along y: still height 20
  m = build_mesh(slab(), p);
  ASSERT_TRUE(m.has_value());
  EXPECT_NEAR(height(*m), 20.0, 1e-9);

  p.direction = Eigen::Vector3d(1, 1, 0);  // diagonal: height is the box's extent along (1,1,0)/√2
  m = build_mesh(slab(), p);
  ASSERT_TRUE(m.has_value());
  EXPECT_NEAR(height(*m), 30.0 / std::sqrt(2.0), 1e-6);
  EXPECT_NEAR(m->summary.bbox_min_mm.z(), 0.0, 1e-12);
}

TEST(BuildDirection, RotationIsProperAndAxisPermutationsAreExact) {
  for (BuildAxis a : {BuildAxis::x, BuildAxis::y, BuildAxis::z}) {
    MeshParams p;
    p.axis = a;
    const Eigen::Matrix3d r = build_frame_rotation(p);
    EXPECT_DOUBLE_EQ(r.determinant(), 1.0);
    const Eigen::Vector3d up = a == BuildAxis::x ? Eigen::Vector3d::UnitX()
                               : a == BuildAxis::y ? Eigen::Vector3d::UnitY()
                                                   : Eigen::Vector3d::UnitZ();
    EXPECT_EQ(r * up, Eigen::Vector3d::UnitZ());
  }
  MeshParams p;
  p.direction = Eigen::Vector3d(0.3, -0.5, 0.8);
  const Eigen::Matrix3d r = build_frame_rotation(p);
  EXPECT_NEAR(r.determinant(), 1.0, 1e-12);
  EXPECT_TRUE((r * p.direction->normalized()).isApprox(Eigen::Vector3d::UnitZ(), 1e-12));
}

TEST(BuildDirection, ZeroOrNonFiniteDirectionIsRejected) {
  MeshParams p;
  p.direction = Eigen::Vector3d::Zero();
  auto m = build_mesh(slab(), p);
  ASSERT_FALSE(m.has_value());
  EXPECT_EQ(m.error().code, ErrorCode::invalid_argument);
  EXPECT_NE(m.error().message.find("direction"), std::string::npos);
  p.direction = Eigen::Vector3d(std::numeric_limits<double>::infinity(), 0, 1);
  EXPECT_FALSE(build_mesh(slab(), p).has_value());
}

}  // namespace
}  // namespace lamina
