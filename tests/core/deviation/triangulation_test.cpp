// Polygon-with-holes triangulation (ear clipping with hole bridges): every vertex used, n + 2h − 2
// triangles, the area of the polygon, and a closed edge structure (every boundary edge once,
// every inner edge twice in opposite directions), on hand-made and seeded random polygons.
#include "geometry/polygon_triangulation.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <map>
#include <numbers>
#include <random>
#include <string>

namespace lamina {
namespace {

using geometry_detail::triangulate_polygon_with_holes;
using Tris = std::vector<std::array<std::int32_t, 3>>;

std::vector<Eigen::Vector2d> all_points(const Polygon2& outer, const std::vector<Polygon2>& holes) {
  std::vector<Eigen::Vector2d> pts(outer.begin(), outer.end());
  for (const auto& h : holes) pts.insert(pts.end(), h.begin(), h.end());
  return pts;
}

double tri_area(const std::vector<Eigen::Vector2d>& p, const std::array<std::int32_t, 3>& t) {
  const auto& a = p[static_cast<std::size_t>(t[0])];
  const auto& b = p[static_cast<std::size_t>(t[1])];
  const auto& c = p[static_cast<std::size_t>(t[2])];
  return 0.5 * ((b.x() - a.x()) * (c.y() - a.y()) - (b.y() - a.y()) * (c.x() - a.x()));
}

// Empty when the triangles close the polygon's boundary exactly: each boundary edge (in ring
// order) used once in its own direction, every other edge once in each direction.
std::string edge_problem(const Polygon2& outer, const std::vector<Polygon2>& holes, const Tris& tris) {
  std::map<std::pair<int, int>, int> directed;
  for (const auto& t : tris)
    for (int k = 0; k < 3; ++k) ++directed[{t[static_cast<std::size_t>(k)], t[static_cast<std::size_t>((k + 1) % 3)]}];
  std::map<std::pair<int, int>, int> boundary;
  int start = 0;
  auto add_ring = [&](const Polygon2& ring) {
    const int n = static_cast<int>(ring.size());
    for (int i = 0; i < n; ++i) ++boundary[{start + i, start + (i + 1) % n}];
    start += n;
  };
  add_ring(outer);
  for (const auto& h : holes) add_ring(h);
  for (const auto& [e, count] : boundary) {
    if (directed[e] != 1) return "boundary edge " + std::to_string(e.first) + "-" + std::to_string(e.second) + " used " +
                                 std::to_string(directed[e]) + " times";
    if (directed.count({e.second, e.first}) && directed[{e.second, e.first}] != 0)
      return "boundary edge " + std::to_string(e.first) + "-" + std::to_string(e.second) + " also used backwards";
  }
  for (const auto& [e, count] : directed) {
    if (count == 0 || boundary.count(e)) continue;
    if (count != 1) return "edge used " + std::to_string(count) + " times the same way";
    const auto back = directed.find({e.second, e.first});
    if (back == directed.end() || back->second != 1) return "inner edge without its twin";
  }
  return {};
}

Polygon2 reversed(Polygon2 p) {
  std::reverse(p.begin(), p.end());
  return p;
}

Polygon2 rect(double x0, double y0, double x1, double y1) { return {{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}}; }

void expect_tiling(const Polygon2& outer, const std::vector<Polygon2>& holes, const std::string& what) {
  const Tris tris = triangulate_polygon_with_holes(outer, holes);
  std::size_t n = outer.size();
  for (const auto& h : holes) n += h.size();
  ASSERT_EQ(tris.size(), n + 2 * holes.size() - 2) << what;
  const auto pts = all_points(outer, holes);
  double area = 0.0, want = signed_area_mm2(outer);
  for (const auto& h : holes) want += signed_area_mm2(h);
  double smallest = 1e300;
  for (const auto& t : tris) {
    const double a = tri_area(pts, t);
    smallest = std::min(smallest, a);
    area += a;
  }
  EXPECT_GT(smallest, 0.0) << what << ": a triangle is flat or turned over";
  EXPECT_NEAR(area, want, 1e-9 * std::abs(want)) << what;
  EXPECT_EQ(edge_problem(outer, holes, tris), "") << what;
}

TEST(Triangulation, SquareWithThreeHoles) {
  const Polygon2 outer = rect(0, 0, 10, 10);
  const std::vector<Polygon2> holes{reversed(rect(1, 1, 3, 3)), reversed(rect(5, 1, 9, 4)),
                                    reversed(rect(2, 6, 8, 8))};
  expect_tiling(outer, holes, "square with three holes");
}

TEST(Triangulation, CollinearRunsNeverMakeFlatTriangles) {
  // A rectangle with stations every unit along its sides (like a plan's outline) and a hole
  // whose sides are collinear with points of the outer.
  Polygon2 outer;
  for (int x = 0; x < 10; ++x) outer.emplace_back(x, 0);
  for (int y = 0; y < 4; ++y) outer.emplace_back(10, y);
  for (int x = 10; x > 0; --x) outer.emplace_back(x, 4);
  for (int y = 4; y > 0; --y) outer.emplace_back(0, y);
  Polygon2 hole;
  for (int x = 2; x < 8; ++x) hole.emplace_back(x, 1);
  for (int x = 8; x > 2; --x) hole.emplace_back(x, 3);
  hole.emplace_back(2, 2);
  expect_tiling(outer, {}, "rectangle");
  expect_tiling(outer, {reversed(hole)}, "rectangle with slot");
}

TEST(Triangulation, HolesSharingTheRightmostColumn) {
  // Ties in Eberly's order and rays through vertices: holes whose rightmost points share x and y
  // with outer vertices.
  const Polygon2 outer{{0, 0}, {6, 0}, {6, 2}, {8, 2}, {8, 4}, {6, 4}, {6, 6}, {0, 6}};
  const std::vector<Polygon2> holes{reversed(rect(1, 1, 3, 2)), reversed(rect(1, 4, 3, 5)), reversed(rect(4, 2, 5, 4))};
  expect_tiling(outer, holes, "tied holes");
}

TEST(Triangulation, RingsGivenTheOtherWayAreWalkedBackwards) {
  const Polygon2 outer = reversed(rect(0, 0, 4, 4));  // clockwise
  const Polygon2 hole = rect(1, 1, 2, 2);              // counter-clockwise
  const Tris tris = triangulate_polygon_with_holes(outer, {hole});
  ASSERT_EQ(tris.size(), 8u + 2 - 2);
  const auto pts = all_points(outer, {hole});
  double area = 0.0;
  for (const auto& t : tris) {
    EXPECT_GT(tri_area(pts, t), 0.0);
    area += tri_area(pts, t);
  }
  EXPECT_NEAR(area, 15.0, 1e-12);
}

TEST(Triangulation, CoincidentPointsKeepTheCount) {
  // Two stations at one corner (what a plan with per-side normals gives): a zero-length edge.
  const Polygon2 outer{{0, 0}, {4, 0}, {4, 0}, {4, 4}, {0, 4}};
  const Tris tris = triangulate_polygon_with_holes(outer, {});
  EXPECT_EQ(tris.size(), 3u);
  EXPECT_EQ(edge_problem(outer, {}, tris), "");
}

// Ring star-shaped about c, counter-clockwise: m vertices at jittered angles (each in its own
// m-th of the turn, so c sees every edge under less than half a turn), radii in [r_min, r_max].
Polygon2 random_star(std::mt19937& rng, Eigen::Vector2d c, int m, double r_min, double r_max) {
  std::uniform_real_distribution<double> jitter(0.0, 0.45), rad(r_min, r_max);
  std::vector<double> phis;
  for (int i = 0; i < m; ++i) phis.push_back(2.0 * std::numbers::pi * (i + jitter(rng)) / m);
  Polygon2 ring;
  for (double phi : phis) ring.push_back(c + rad(rng) * Eigen::Vector2d(std::cos(phi), std::sin(phi)));
  return ring;
}

TEST(Triangulation, SeededRandomStarsWithHoles) {
  std::mt19937 rng(20240611);
  std::uniform_int_distribution<int> verts(5, 160), hole_count(0, 6), hole_verts(3, 30);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (int trial = 0; trial < 300; ++trial) {
    const Polygon2 outer = random_star(rng, {0, 0}, verts(rng), 50.0, 100.0);
    // Holes: small stars inside the disc the outer's edges keep clear, apart from each other.
    double clear_r = 1e300;
    for (std::size_t i = 0; i < outer.size(); ++i) {
      const Eigen::Vector2d a = outer[i], b = outer[(i + 1) % outer.size()];
      const double t = std::clamp(-a.dot(b - a) / (b - a).squaredNorm(), 0.0, 1.0);
      clear_r = std::min(clear_r, (a + t * (b - a)).norm());
    }
    std::vector<Polygon2> holes;
    std::vector<std::pair<Eigen::Vector2d, double>> placed;
    const int want = hole_count(rng);
    for (int tries = 0; tries < 200 && static_cast<int>(holes.size()) < want; ++tries) {
      const Eigen::Vector2d c(0.7 * clear_r * unit(rng), 0.7 * clear_r * unit(rng));
      const double r = 0.1 * clear_r * (1.0 + 0.5 * unit(rng));
      if (c.norm() + r > clear_r - 0.5) continue;
      bool clear = true;
      for (const auto& [pc, pr] : placed) clear = clear && (pc - c).norm() > pr + r + 0.5;
      if (!clear) continue;
      placed.emplace_back(c, r);
      holes.push_back(reversed(random_star(rng, c, hole_verts(rng), 0.3 * r, r)));
    }
    expect_tiling(outer, holes, "trial " + std::to_string(trial));
    if (HasFatalFailure() || HasNonfatalFailure()) break;
  }
}

TEST(Triangulation, ManyVerticesAndHoles) {
  // 20000 jagged outer vertices and 40 holes in a row (the ear tests go through a grid here).
  std::mt19937 rng(5);
  const Polygon2 outer = random_star(rng, {0, 0}, 20000, 90.0, 100.0);
  std::vector<Polygon2> holes;
  for (int i = 0; i < 40; ++i)
    holes.push_back(reversed(random_star(rng, {-78.0 + 4.0 * i, (i % 2) * 3.0}, 25, 0.8, 1.5)));
  expect_tiling(outer, holes, "20000 vertices, 40 holes");
}

TEST(Triangulation, LongCollinearSidesWithTheGrid) {
  Polygon2 outer;
  for (int x = 0; x < 100; ++x) outer.emplace_back(x, 0);
  for (int y = 0; y < 10; ++y) outer.emplace_back(100, y);
  for (int x = 100; x > 0; --x) outer.emplace_back(x, 10);
  for (int y = 10; y > 0; --y) outer.emplace_back(0, y);
  std::vector<Polygon2> holes;
  for (int k = 0; k < 8; ++k) holes.push_back(reversed(rect(2 + 12 * k, 2, 10 + 12 * k, 8)));
  expect_tiling(outer, holes, "long rectangle with holes");
}


// Rings of 20,000 vertices (issue 16, item 12): the ear tests of large rings look only at reflex
// corners near the ear, so the work (counted, not timed) stays about n log n where testing every
// corner was n² (a 100,000-vertex ring: 127 ms at 10,000 → seconds at 100,000).
TEST(Triangulation, LargeRingsTileInAboutLinearWork) {
  const int n = 20000;
  Polygon2 circle, star, spiral_in, spiral_out, comb{{0.0, -1.0}, {5000.0, -1.0}};
  for (int i = 0; i < n; ++i) {
    const double a = 2 * std::numbers::pi * i / n;
    circle.emplace_back(std::cos(a), std::sin(a));
    star.push_back((i % 2 == 1 ? 0.5 : 1.0) * circle.back());
    const double t = 8 * std::numbers::pi * i / n;
    spiral_in.emplace_back((1.0 + t) * std::cos(t), (1.0 + t) * std::sin(t));
    spiral_out.emplace_back((1.5 + t) * std::cos(t), (1.5 + t) * std::sin(t));
  }
  for (int k = 4999; k >= 0; --k)
    for (const auto& p : {Eigen::Vector2d(k + 0.5, 0), Eigen::Vector2d(k + 0.5, 10), Eigen::Vector2d(k, 10),
                          Eigen::Vector2d(k, 0)})
      comb.push_back(p);
  Polygon2 spiral(spiral_in.begin(), spiral_in.end());
  spiral.insert(spiral.end(), spiral_out.rbegin(), spiral_out.rend());
  if (signed_area_mm2(spiral) < 0) spiral = reversed(spiral);
  for (const auto& [what, ring] : {std::pair{"circle", circle}, {"star", star}, {"spiral", spiral}, {"comb", comb}}) {
    geometry_detail::TriangulationWork work;
    const Tris tris = triangulate_polygon_with_holes(ring, {}, geometry_detail::kCapStraightSine, &work);
    EXPECT_FALSE(work.exhausted) << what;
    EXPECT_LT(work.steps, 20 * ring.size() * std::bit_width(ring.size())) << what << ": " << work.steps / ring.size();
    expect_tiling(ring, {}, what);
  }
}

TEST(Triangulation, ASelfCrossingLargeRingStaysBoundedAndClosed) {
  // Random points in random order: no proper ears. The step budget ends the search and the
  // rest is cut corner by corner: still n − 2 triangles on every boundary edge once.
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Polygon2 noise;
  for (int i = 0; i < 20000; ++i) noise.emplace_back(u(rng), u(rng));
  if (signed_area_mm2(noise) < 0) noise = reversed(noise);  // as given, so the edges read the same way
  geometry_detail::TriangulationWork work;
  const Tris tris = triangulate_polygon_with_holes(noise, {}, geometry_detail::kCapStraightSine, &work);
  EXPECT_EQ(tris.size(), noise.size() - 2);
  EXPECT_TRUE(work.exhausted);
  EXPECT_LT(work.steps, (std::uint64_t{1} << 20) + 33 * noise.size() * std::bit_width(noise.size()));
  EXPECT_EQ(edge_problem(noise, {}, tris), "");
}

}  // namespace
}  // namespace lamina
