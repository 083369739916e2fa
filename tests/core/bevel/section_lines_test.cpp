// SectionLines::exit_crossing, the corresponding-point query the layering and the bevel plan ask
// millions of times: against a brute force over every contour vector of the slice, for both
// picks, and the rule for two crossings equally far from u = 0; contains against even-odd.
#include "lamina/core/section_lines.hpp"
#include "lamina/core/slice.hpp"

#include "mesh_soups.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <optional>
#include <random>

namespace lamina {
namespace {

Mesh built(const TriangleSoup& soup) {
  auto m = build_mesh(soup, MeshParams{});
  EXPECT_TRUE(m.has_value());
  return std::move(*m);
}

Slice slice_at(const Mesh& mesh, double z) {
  auto s = slice_mesh(mesh, std::vector<double>{z}, SliceParams{});
  EXPECT_TRUE(s && s->size() == 1);
  return s->front();
}

// Every exit crossing of the line with u in [u_min, u_max], by the same rule as the grid's
// (material on the left of each loop vector), the pick taken over all of them.
std::optional<double> brute_force(const Slice& slice, const Eigen::Vector2d& o, const Eigen::Vector2d& d, double u_min,
                                  double u_max, CrossingPick pick) {
  auto cross = [](const Eigen::Vector2d& a, const Eigen::Vector2d& b) { return a.x() * b.y() - a.y() * b.x(); };
  std::optional<double> best;
  for (const Loop& l : slice.loops)
    for (std::size_t i = 0; i < l.size(); ++i) {
      const Eigen::Vector2d a = l.points[i], e = l.points[(i + 1) % l.size()] - a;
      const double denom = cross(d, e);
      if (std::abs(denom) < 1e-300) continue;
      const double u = cross(a - o, e) / denom, t = cross(a - o, d) / denom;
      if (t < 0 || t >= 1 || u < u_min || u > u_max || Eigen::Vector2d(-e.y(), e.x()).dot(d) >= 0) continue;
      const auto key = [&](double v) { return pick == CrossingPick::largest ? -v : std::abs(v); };
      if (!best || key(u) < key(*best) || (key(u) == key(*best) && u < *best)) best = u;
    }
  return best;
}

// Two 1 mm-deep boxes along x, [-3, -1] and [0.5, 1]: a line along +x through y = 0.5 leaves
// material at u = -1 and at u = +1, equally far from its origin at x = 0.
TEST(SectionLines, TwoExitsEquallyFarGoToTheSmallerU) {
  const Mesh m = built(mesh_test::append(mesh_test::box({-3, 0, 0}, {-1, 1, 1}), mesh_test::box({0.5, 0, 0}, {1, 1, 1})));
  const SectionLines lines(m, slice_at(m, 0.5));
  const Eigen::Vector2d o(0, 0.5), d(1, 0);
  const auto nearest = lines.exit_crossing(o, d, -5, 5, CrossingPick::nearest_zero);
  ASSERT_TRUE(nearest);
  EXPECT_NEAR(nearest->u_mm, -1, 1e-9);
  const auto largest = lines.exit_crossing(o, d, -5, 5, CrossingPick::largest);
  ASSERT_TRUE(largest);
  EXPECT_NEAR(largest->u_mm, 1, 1e-9);
  EXPECT_FALSE(lines.exit_crossing(o, d, -0.9, 0.9, CrossingPick::nearest_zero)) << "both outside the range";
  const auto right_only = lines.exit_crossing(o, d, -0.9, 5, CrossingPick::nearest_zero);
  ASSERT_TRUE(right_only);
  EXPECT_NEAR(right_only->u_mm, 1, 1e-9);
}

// Random lines through a sphere beside a box, every range and both picks: the grid's
// answer is the brute force's, to rounding.
TEST(SectionLines, EveryQueryAnswersAsABruteForceOverTheWholeSlice) {
  TriangleSoup soup = mesh_test::append(mesh_test::uv_sphere(20, 64, 32, {0, 0, 0}), mesh_test::box({25, -10, -10}, {45, 10, 10}));
  const Mesh m = built(soup);
  const Slice slice = slice_at(m, 10.0 + 3.3);  // lowered: z 0 is the sphere's bottom
  const SectionLines lines(m, slice);
  std::mt19937 rng(21);
  std::uniform_real_distribution<double> x(-30, 55), y(-30, 30), angle(0, 2 * std::numbers::pi), w(0, 40);
  int found = 0;
  for (int q = 0; q < 4000; ++q) {
    const Eigen::Vector2d o(x(rng), y(rng));
    const double a = angle(rng);
    const Eigen::Vector2d d(std::cos(a), std::sin(a));
    const double u_min = -w(rng), u_max = q % 5 == 0 ? -u_min * 0.3 : w(rng);
    for (const CrossingPick pick : {CrossingPick::nearest_zero, CrossingPick::largest}) {
      const auto got = lines.exit_crossing(o, d, u_min, u_max, pick);
      const auto want = brute_force(slice, o, d, u_min, u_max, pick);
      ASSERT_EQ(got.has_value(), want.has_value()) << "query " << q;
      if (!got) continue;
      ++found;
      ASSERT_NEAR(got->u_mm, *want, 1e-9) << "query " << q << (pick == CrossingPick::largest ? " largest" : " nearest");
    }
  }
  EXPECT_GT(found, 2000) << "most random lines cross the section";
}

// Even-odd over every contour vector of the slice: a horizontal ray to +x.
bool brute_contains(const Slice& slice, const Eigen::Vector2d& p) {
  bool inside = false;
  for (const Loop& l : slice.loops)
    for (std::size_t i = 0; i < l.size(); ++i) {
      const Eigen::Vector2d a = l.points[i], b = l.points[(i + 1) % l.size()];
      if ((a.y() > p.y()) == (b.y() > p.y())) continue;
      if (a.x() + (p.y() - a.y()) * (b.x() - a.x()) / (b.y() - a.y()) > p.x()) inside = !inside;
    }
  return inside;
}

TEST(SectionLines, ContainsAnswersAsEvenOddOverTheWholeSlice) {
  // A sphere between two boxes, and a point cloud over and around them; half the points
  // near the contours, where a cell holds vectors.
  TriangleSoup soup = mesh_test::append(mesh_test::uv_sphere(20, 64, 32, {0, 0, 0}), mesh_test::box({25, -10, -10}, {45, 10, 10}));
  soup = mesh_test::append(soup, mesh_test::box({-60, -30, -10}, {-35, 30, 10}));
  const Mesh m = built(soup);
  for (const double z : {13.3, 20.0, 29.9}) {
    const Slice slice = slice_at(m, z);
    ASSERT_FALSE(slice.loops.empty());
    const SectionLines lines(m, slice, SectionQueries::crossings_and_contains);
    const SectionLines without(m, slice);  // contains() over every vector
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> x(-70, 60), y(-40, 40), near(-0.3, 0.3);
    int inside = 0, outside = 0;
    for (int q = 0; q < 20000; ++q) {
      Eigen::Vector2d p(x(rng), y(rng));
      if (q % 2 == 1) {  // near a vertex of a contour
        const Loop& l = slice.loops[static_cast<std::size_t>(q) % slice.loops.size()];
        p = l.points[static_cast<std::size_t>(q / 2) % l.size()] + Eigen::Vector2d(near(rng), near(rng));
      }
      const bool want = brute_contains(slice, p);
      ASSERT_EQ(lines.contains(p), want) << "z " << z << " query " << q << " at " << p.transpose();
      if (q % 10 == 0) {
        ASSERT_EQ(without.contains(p), want) << "z " << z << " query " << q;
      }
      (want ? inside : outside) += 1;
    }
    EXPECT_GT(inside, 2000);
    EXPECT_GT(outside, 2000);
    // The section is closed: a point on a contour vector, or at its corner, is material.
    for (const Loop& l : slice.loops)
      for (std::size_t i = 0; i < l.size(); i += 7) {
        const Eigen::Vector2d a = l.points[i], b = l.points[(i + 1) % l.size()];
        for (const Eigen::Vector2d& on : {a, Eigen::Vector2d(0.5 * (a + b))}) {
          ASSERT_TRUE(lines.contains(on)) << "z " << z << " loop vertex " << i;
          ASSERT_TRUE(without.contains(on)) << "z " << z << " loop vertex " << i;
        }
      }
  }
}

}  // namespace
}  // namespace lamina
