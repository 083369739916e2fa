// Point-to-triangle distance and the triangle tree behind max_mm: against dense sampling of the
// triangles (every Voronoi region of a triangle, degenerate triangles), and the tree against a
// brute-force scan, including its early stop.
#include "geometry/closest_point.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

namespace lamina {
namespace {

using geometry_detail::point_triangle_distance2;
using geometry_detail::TriangleTree;

// Smallest distance from p to points of the triangle on a barycentric grid of n steps: an upper
// bound of the true distance, within the grid's spacing of it.
double sampled_distance(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                        const Eigen::Vector3d& c, int n) {
  double best = 1e300;
  for (int i = 0; i <= n; ++i)
    for (int j = 0; i + j <= n; ++j) {
      const Eigen::Vector3d q = a + (b - a) * (double(i) / n) + (c - a) * (double(j) / n);
      best = std::min(best, (q - p).norm());
    }
  return best;
}

TEST(ClosestPoint, MatchesDenseSamplingEverywhere) {
  std::mt19937 rng(99);
  std::uniform_real_distribution<double> u(-2.0, 2.0);
  const int n = 200;
  for (int trial = 0; trial < 400; ++trial) {
    const Eigen::Vector3d a(u(rng), u(rng), u(rng)), b(u(rng), u(rng), u(rng)), c(u(rng), u(rng), u(rng));
    const Eigen::Vector3d p(2 * u(rng), 2 * u(rng), 2 * u(rng));
    const double d = std::sqrt(point_triangle_distance2(p, a, b, c));
    const double s = sampled_distance(p, a, b, c, n);
    const double spacing = std::max({(b - a).norm(), (c - a).norm(), (c - b).norm()}) / n;
    EXPECT_LE(d, s + 1e-12) << trial;
    EXPECT_GE(d, s - spacing) << trial;
  }
}

TEST(ClosestPoint, DegenerateTrianglesAreTheirEdges) {
  const Eigen::Vector3d a(0, 0, 0), b(2, 0, 0), c(1, 0, 0);  // collinear
  EXPECT_NEAR(std::sqrt(point_triangle_distance2({1, 1, 0}, a, b, c)), 1.0, 1e-15);
  EXPECT_NEAR(std::sqrt(point_triangle_distance2({3, 0, 0}, a, b, c)), 1.0, 1e-15);
  EXPECT_NEAR(std::sqrt(point_triangle_distance2({0, 0, 2}, a, a, a)), 2.0, 1e-15);  // a point
}

TEST(TriangleTreeTest, AgreesWithBruteForce) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(0.0, 50.0), small(-1.0, 1.0);
  std::vector<Eigen::Vector3d> vertices;
  std::vector<std::array<std::int32_t, 3>> faces;
  for (int t = 0; t < 3000; ++t) {
    const Eigen::Vector3d c(u(rng), u(rng), 0.2 * u(rng));
    const auto base = static_cast<std::int32_t>(vertices.size());
    for (int k = 0; k < 3; ++k) vertices.push_back(c + Eigen::Vector3d(small(rng), small(rng), small(rng)));
    faces.push_back({base, base + 1, base + 2});
  }
  for (const auto threads : {geometry_detail::Threads::one, geometry_detail::Threads::many}) {
    const TriangleTree tree(vertices, faces, threads);
    std::int32_t hint = -1;
    for (int q = 0; q < 500; ++q) {
      const Eigen::Vector3d p(u(rng) * 1.2 - 5, u(rng) * 1.2 - 5, 0.5 * u(rng) - 5);
      double brute = 1e300;
      for (const auto& f : faces)
        brute = std::min(brute, point_triangle_distance2(p, vertices[f[0]], vertices[f[1]], vertices[f[2]]));
      brute = std::sqrt(brute);
      EXPECT_NEAR(tree.distance(p, 0.0, hint), brute, 1e-12) << q;
      // With an early stop at `enough`: exact above it, at most `enough` below it.
      const double enough = 1.5;
      const double d = tree.distance(p, enough, hint);
      if (brute > enough)
        EXPECT_NEAR(d, brute, 1e-12);
      else
        EXPECT_LE(d, enough);
      EXPECT_GE(d, brute - 1e-12);
    }
  }
}

TEST(TriangleTreeTest, MortonOrderKeepsThePoints) {
  std::mt19937 rng(8);
  std::uniform_real_distribution<double> u(-10.0, 10.0);
  std::vector<Eigen::Vector3d> pts;
  for (int i = 0; i < 1000; ++i) pts.emplace_back(u(rng), u(rng), u(rng));
  auto sorted = pts;
  geometry_detail::sort_morton(sorted, geometry_detail::Threads::many);
  auto key = [](const Eigen::Vector3d& v) { return std::tuple(v.x(), v.y(), v.z()); };
  auto a = pts, b = sorted;
  std::sort(a.begin(), a.end(), [&](auto& x, auto& y) { return key(x) < key(y); });
  std::sort(b.begin(), b.end(), [&](auto& x, auto& y) { return key(x) < key(y); });
  EXPECT_EQ(a, b);
  // Consecutive points are near each other on average (far nearer than in random order).
  double step_sorted = 0, step_random = 0;
  for (std::size_t i = 1; i < pts.size(); ++i) {
    step_sorted += (sorted[i] - sorted[i - 1]).norm();
    step_random += (pts[i] - pts[i - 1]).norm();
  }
  EXPECT_LT(step_sorted, 0.5 * step_random);
}

// The nodes' boxes are floats: rounded outwards they still hold their triangles where a float
// cannot say the coordinates (a float's step at 100 km is 8 mm, the triangles here are 1 µm
// apart), so a point on a triangle is found on it. Rounded to nearest, boxes would cut off
// corners and a query would settle for a neighbour.
TEST(TriangleTreeTest, FloatBoxesStillHoldTheirTrianglesFarFromTheOrigin) {
  std::vector<Eigen::Vector3d> vertices;
  std::vector<std::array<std::int32_t, 3>> faces;
  const Eigen::Vector3d far(1e5 + 0.0031, -2e5 + 0.0057, 3e4 + 0.0013);
  for (int i = 0; i < 400; ++i) {
    const Eigen::Vector3d c = far + Eigen::Vector3d(1e-3 * (i % 20), 1e-3 * (i / 20), 1e-4 * (i % 7));
    const auto base = static_cast<std::int32_t>(vertices.size());
    vertices.push_back(c);
    vertices.push_back(c + Eigen::Vector3d(4e-4, 0, 0));
    vertices.push_back(c + Eigen::Vector3d(0, 4e-4, 1e-4));
    faces.push_back({base, base + 1, base + 2});
  }
  const TriangleTree tree(vertices, faces, geometry_detail::Threads::one);
  for (std::size_t v = 0; v < vertices.size(); ++v) {
    std::int32_t hint = -1;
    EXPECT_EQ(tree.distance(vertices[v], 0.0, hint), 0.0) << v;
  }
}

// The tree's surface samples are every vertex a triangle uses, once, and every triangle's
// centroid: an unused vertex is no surface point, a shared one is not sampled twice.
TEST(TriangleTreeTest, SurfaceSamplesAreTheUsedVerticesOnceAndEveryCentroid) {
  std::vector<Eigen::Vector3d> vertices{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}, {9, 9, 9}};  // 4 unused
  std::vector<std::array<std::int32_t, 3>> faces{{0, 1, 2}, {1, 3, 2}};
  const TriangleTree tree(vertices, faces, geometry_detail::Threads::one);
  ASSERT_EQ(tree.surface_sample_count(), 4u + 2u);
  auto key = [](const Eigen::Vector3d& v) { return std::tuple(v.x(), v.y(), v.z()); };
  std::vector<std::tuple<double, double, double>> got, want;
  for (std::size_t i = 0; i < tree.surface_sample_count(); ++i) got.push_back(key(tree.surface_sample(i)));
  for (int v = 0; v < 4; ++v) want.push_back(key(vertices[static_cast<std::size_t>(v)]));
  for (const auto& f : faces) want.push_back(key((vertices[f[0]] + vertices[f[1]] + vertices[f[2]]) / 3.0));
  std::sort(got.begin(), got.end());
  std::sort(want.begin(), want.end());
  EXPECT_EQ(got, want);
}

}  // namespace
}  // namespace lamina
