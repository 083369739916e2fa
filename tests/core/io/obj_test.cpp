// OBJ: corner forms, negative indices, skipped statements, polygon triangulation (convex and
// non-convex, in tilted planes), index errors with line numbers.
#include "io_test_util.hpp"
#include "lamina/core/mesh_io.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>

namespace lamina {
namespace {

using test::find_note;
using test::triangle_cross;
using test::unsigned_area;

TEST(Obj, ReadsTrianglesWithEveryCornerFormAndSkipsOtherStatements) {
  const std::string text =
      "# comment line\n"
      "mtllib part.mtl\n"
      "o body\n"
      "g group1\n"
      "v 0 0 0\n"
      "v 1.5 0 0 1.0\n"          // optional w
      "v 0 2.25 0 0.5 0.5 0.5\n"  // vertex colour
      "v 0 0 -3e-2   # trailing comment\n"
      "vt 0 0\nvt 1 0\nvt 0 1\n"
      "vn 0 0 1\n"
      "usemtl steel\n"
      "s off\n"
      "f 1 2 3\n"
      "f 1/1 2/2 4/3\n"
      "f 1//1 3//1 4//1\r\n"
      "f 2/2/1 3/3/1 4/1/1\n"
      "l 1 2\n";
  auto soup = parse_obj(text, "forms.obj");
  ASSERT_TRUE(soup) << soup.error().message;
  EXPECT_EQ(soup->format, "obj");
  ASSERT_EQ(soup->triangle_count(), 4u);
  const Eigen::Vector3f v1(0, 0, 0), v2(1.5f, 0, 0), v3(0, 2.25f, 0), v4(0, 0, -3e-2f);
  const Eigen::Vector3f expected[12] = {v1, v2, v3, v1, v2, v4, v1, v3, v4, v2, v3, v4};
  for (int i = 0; i < 12; ++i) EXPECT_EQ(soup->corners[i], expected[i]) << "corner " << i;
  EXPECT_TRUE(soup->notes.empty()) << soup->notes.front().code;
}

TEST(Obj, CrOnlyLineEndsAreLineEnds) {
  auto soup = parse_obj("v 0 0 0\rv 1 0 0\rv 0 1 0\rv 0 0 1\rf 1 2 3\rf 1 3 4 # c\rx bad line\r", "mac.obj");
  ASSERT_TRUE(soup) << soup.error().message;
  ASSERT_EQ(soup->triangle_count(), 2u);
  EXPECT_EQ(soup->corners[5], Eigen::Vector3f(0, 0, 1));
  const ReadNote* note = find_note(*soup, "unknown_statements");
  ASSERT_NE(note, nullptr);
  EXPECT_NE(note->message.find("on line 7"), std::string::npos) << note->message;
}

TEST(Obj, NegativeIndicesAreRelativeToVerticesReadSoFar) {
  const std::string text =
      "v 0 0 0\nv 1 0 0\nv 0 1 0\n"
      "f -3 -2 -1\n"  // 1 2 3
      "v 5 5 5\n"
      "f -4/-1/-1 -1 -2\n"  // 1 4 3
      "f 2 -1 -3\n";        // 2 4 2
  auto soup = parse_obj(text, "neg.obj");
  ASSERT_TRUE(soup) << soup.error().message;
  ASSERT_EQ(soup->triangle_count(), 3u);
  const Eigen::Vector3f v1(0, 0, 0), v2(1, 0, 0), v3(0, 1, 0), v4(5, 5, 5);
  const Eigen::Vector3f expected[9] = {v1, v2, v3, v1, v4, v3, v2, v4, v2};
  for (int i = 0; i < 9; ++i) EXPECT_EQ(soup->corners[i], expected[i]) << "corner " << i;
}

TEST(Obj, ConvexQuadBecomesTwoTrianglesWithTheSameWinding) {
  auto soup = parse_obj("v 0 0 0\nv 2 0 0\nv 2 3 0\nv 0 3 0\nf 1 2 3 4\n", "quad.obj");
  ASSERT_TRUE(soup) << soup.error().message;
  ASSERT_EQ(soup->triangle_count(), 2u);
  EXPECT_DOUBLE_EQ(unsigned_area(*soup), 6.0);
  for (std::size_t t = 0; t < 2; ++t) EXPECT_GT(triangle_cross(*soup, t).z(), 0.0) << t;
  EXPECT_NE(find_note(*soup, "polygons_triangulated"), nullptr);
}

// Writes a polygon as OBJ, after mapping its 2D corners into the plane spanned by (u, w) at `origin`.
std::string polygon_obj(const std::vector<Eigen::Vector2d>& pts, const Eigen::Vector3d& origin, const Eigen::Vector3d& u,
                        const Eigen::Vector3d& w) {
  std::string text;
  for (const auto& p : pts) {
    const Eigen::Vector3d q = origin + p.x() * u + p.y() * w;
    text += "v " + std::to_string(q.x()) + " " + std::to_string(q.y()) + " " + std::to_string(q.z()) + "\n";
  }
  text += "f";
  for (std::size_t i = 1; i <= pts.size(); ++i) text += " " + std::to_string(i);
  return text + "\n";
}

// Triangulation of a simple polygon is right when the triangles' unsigned areas add up to the
// polygon's area and every triangle faces the polygon's way (a fan across a reflex corner
// produces a flipped triangle and too much area).
void expect_exact_cover(const std::vector<Eigen::Vector2d>& pts, double area, const Eigen::Vector3d& u,
                        const Eigen::Vector3d& w) {
  const Eigen::Vector3d normal = u.cross(w).normalized();
  auto soup = parse_obj(polygon_obj(pts, Eigen::Vector3d(10, -20, 30), u, w), "poly.obj");
  ASSERT_TRUE(soup) << soup.error().message;
  ASSERT_EQ(soup->triangle_count(), pts.size() - 2);
  const double scale = u.cross(w).norm();
  EXPECT_NEAR(unsigned_area(*soup), area * scale, 1e-4 * area * scale);
  for (std::size_t t = 0; t < soup->triangle_count(); ++t) {
    const Eigen::Vector3d c = triangle_cross(*soup, t);
    EXPECT_GT(c.dot(normal), 0.0) << "triangle " << t << " is flipped or degenerate";
    EXPECT_NEAR(c.normalized().dot(normal), 1.0, 1e-4) << "triangle " << t << " leaves the polygon's plane";
  }
}

TEST(Obj, NonConvexLShapeIsTriangulatedCorrectly) {
  // L-shaped hexagon, area 3, listed from the corner next to the reflex one: a fan from the first
  // corner would cover 4 units of area with one flipped triangle.
  const std::vector<Eigen::Vector2d> l_shape = {{2, 1}, {1, 1}, {1, 2}, {0, 2}, {0, 0}, {2, 0}};
  expect_exact_cover(l_shape, 3.0, Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY());
  // The same in a tilted plane (u, w orthogonal, not unit: area scales by |u × w|).
  expect_exact_cover(l_shape, 3.0, Eigen::Vector3d(1, 1, 0), Eigen::Vector3d(-1, 1, 2));
  // Reversed order (clockwise seen from +z): the Newell normal flips with it.
  std::vector<Eigen::Vector2d> reversed(l_shape.rbegin(), l_shape.rend());
  auto soup = parse_obj(polygon_obj(reversed, Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitX(),
                                    Eigen::Vector3d::UnitY()),
                        "cw.obj");
  ASSERT_TRUE(soup);
  EXPECT_NEAR(unsigned_area(*soup), 3.0, 1e-9);
  for (std::size_t t = 0; t < soup->triangle_count(); ++t) EXPECT_LT(triangle_cross(*soup, t).z(), 0.0) << t;
}

TEST(Obj, NonConvexQuadIsNotFanned) {
  // A dart whose reflex corner is corner 1: the fan (0 1 2), (0 2 3) would flip its first triangle.
  const std::vector<Eigen::Vector2d> dart = {{0, 0}, {2, 1}, {4, 0}, {2, 3}};
  expect_exact_cover(dart, 4.0, Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY());
  expect_exact_cover(dart, 4.0, Eigen::Vector3d(0, 0, 2), Eigen::Vector3d(1, 1, 0));
}

TEST(Obj, StarAndCombPolygonsAreTriangulatedCorrectly) {
  // Five-pointed star, outer radius 2, inner 0.8: area = 5 · R · r · sin(36°).
  std::vector<Eigen::Vector2d> star;
  for (int i = 0; i < 10; ++i) {
    const double r = i % 2 == 0 ? 2.0 : 0.8;
    const double a = std::numbers::pi / 2 + i * std::numbers::pi / 5;
    star.emplace_back(r * std::cos(a), r * std::sin(a));
  }
  expect_exact_cover(star, 5 * 2.0 * 0.8 * std::sin(std::numbers::pi / 5), Eigen::Vector3d(0, 1, 0),
                     Eigen::Vector3d(0, 0, 1));

  // A comb: base 7 × 1 with three teeth 1 × 2 (area 7 + 6 = 13), plus a collinear point on the base.
  const std::vector<Eigen::Vector2d> comb = {{0, 0}, {3.5, 0}, {7, 0}, {7, 3}, {6, 3}, {6, 1}, {4, 1}, {4, 3},
                                             {3, 3}, {3, 1}, {1, 1}, {1, 3}, {0, 3}};
  expect_exact_cover(comb, 13.0, Eigen::Vector3d(0.6, 0, 0.8), Eigen::Vector3d(0, 1, 0));
}

TEST(Obj, DegeneratePolygonsStillGiveOneTriangleFewerThanTwoCorners) {
  // Self-intersecting bow tie, all corners on a line, and a polygon with a NaN corner: no crash,
  // n − 2 triangles, corners taken from the face.
  const std::string text =
      "v 0 0 0\nv 1 1 0\nv 1 0 0\nv 0 1 0\n"
      "v 0 0 5\nv 1 0 5\nv 2 0 5\nv 3 0 5\nv 4 0 5\n"
      "v nan 0 0\n"
      "f 1 2 3 4\n"
      "f 5 6 7 8 9\n"
      "f 1 3 10 2 4\n";
  auto soup = parse_obj(text, "degenerate.obj");
  ASSERT_TRUE(soup) << soup.error().message;
  ASSERT_EQ(soup->triangle_count(), 2u + 3u + 3u);
  // The bow tie's two lobes cancel in the Newell normal, so it is fanned: (1 2 3) and (1 3 4),
  // half a unit each.
  double bow_tie = 0.0;
  for (std::size_t t = 0; t < 2; ++t) bow_tie += 0.5 * triangle_cross(*soup, t).norm();
  EXPECT_NEAR(bow_tie, 1.0, 1e-12);
  for (std::size_t i = 6; i < 15; ++i) EXPECT_EQ(soup->corners[i].z(), 5.0f) << i;  // the collinear face
  for (std::size_t t = 2; t < 5; ++t) EXPECT_EQ(triangle_cross(*soup, t).norm(), 0.0) << t;
  int nan_corners = 0;
  for (std::size_t i = 15; i < 24; ++i) nan_corners += std::isnan(soup->corners[i].x());
  EXPECT_EQ(nan_corners, 2);  // fanned: (0 1 2), (0 2 3), (0 3 4) hold the NaN corner (index 2) twice
  EXPECT_NE(find_note(*soup, "non_finite_coordinates"), nullptr);
}

// The error names the file and the line and says why.
void expect_obj_error(std::string_view text, std::size_t line, std::string_view what) {
  auto r = parse_obj(text, "bad.obj");
  ASSERT_FALSE(r) << "parsed " << r->triangle_count() << " triangles";
  EXPECT_EQ(r.error().code, ErrorCode::parse_error);
  EXPECT_NE(r.error().message.find("bad.obj:" + std::to_string(line) + ":"), std::string::npos) << r.error().message;
  EXPECT_NE(r.error().message.find(what), std::string::npos) << r.error().message;
}

TEST(Obj, IndexAndSyntaxErrorsReportTheLine) {
  const std::string verts = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
  expect_obj_error(verts + "f 1 2 3\nf 1 2 4\n", 5, "vertex index 4 is out of range (the file defines 3 vertices)");
  expect_obj_error(verts + "\n\nf 1 2 3 99/1/1\n", 6, "vertex index 99 is out of range");
  expect_obj_error(verts + "f -1 -2 -4\n", 4, "relative vertex index -4 is out of range");
  expect_obj_error(verts + "f 0 1 2\n", 4, "index 0 is invalid");
  expect_obj_error(verts + "f 1 2\n", 4, "face with 2 vertices");
  expect_obj_error(verts + "f 1 2 x\n", 4, "found 'x'");
  expect_obj_error(verts + "f 1 2 3a\n", 4, "found '3a'");
  expect_obj_error("v 0 0\n", 1, "fewer than 3 coordinates");
  expect_obj_error("v 0 0 zero\n", 1, "expected a vertex coordinate, found 'zero'");
}

TEST(Obj, PositiveIndicesMayReferToLaterVertices) {
  auto soup = parse_obj("f 1 2 3\nv 0 0 0\nv 1 0 0\nv 0 1 0\n", "forward.obj");
  ASSERT_TRUE(soup) << soup.error().message;
  ASSERT_EQ(soup->triangle_count(), 1u);
  EXPECT_EQ(soup->corners[2], Eigen::Vector3f(0, 1, 0));
}

TEST(Obj, NoFacesIsEmptyAndUnknownStatementsAreNoted) {
  auto empty = parse_obj("v 0 0 0\nv 1 0 0\n# nothing else\n", "empty.obj");
  ASSERT_FALSE(empty);
  EXPECT_EQ(empty.error().code, ErrorCode::empty_mesh);

  auto soup = parse_obj("v 0 0 0\nv 1 0 0\nv 0 1 0\nfrobnicate 1 2\nf 1 2 3\n", "odd.obj");
  ASSERT_TRUE(soup) << soup.error().message;
  const ReadNote* note = find_note(*soup, "unknown_statements");
  ASSERT_NE(note, nullptr);
  EXPECT_NE(note->message.find("'frobnicate' on line 4"), std::string::npos) << note->message;
}

}  // namespace
}  // namespace lamina
