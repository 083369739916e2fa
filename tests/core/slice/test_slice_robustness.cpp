// Seeded stress tests: degenerate and overlapping input must never crash the slicer, and the
// union of overlapping bodies must have exactly the area of a rasterised ground truth.
#include "lamina/core/mesh.hpp"
#include "lamina/core/slice.hpp"
#include "mesh_soups.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <set>

namespace lamina {
namespace {

// Exact area of a union of axis-aligned rectangles, by coordinate compression.
double union_area(const std::vector<std::array<double, 4>>& rects) {
  std::vector<double> xs, ys;
  for (const auto& r : rects) {
    xs.insert(xs.end(), {r[0], r[2]});
    ys.insert(ys.end(), {r[1], r[3]});
  }
  std::sort(xs.begin(), xs.end());
  std::sort(ys.begin(), ys.end());
  double area = 0;
  for (std::size_t i = 0; i + 1 < xs.size(); ++i)
    for (std::size_t j = 0; j + 1 < ys.size(); ++j) {
      const double cx = 0.5 * (xs[i] + xs[i + 1]), cy = 0.5 * (ys[j] + ys[j + 1]);
      for (const auto& r : rects)
        if (r[0] < cx && cx < r[2] && r[1] < cy && cy < r[3]) {
          area += (xs[i + 1] - xs[i]) * (ys[j + 1] - ys[j]);
          break;
        }
    }
  return area;
}

// Bodies overlapping at random (a CAD export without the boolean union): every section must be
// the union of the bodies' sections, with its exact area. Boxes are not nested (a shell wholly
// inside another is read as a cavity: see docs/mesh-check.md).
TEST(SliceRobustness, UnionOfRandomOverlappingBoxesHasTheExactArea) {
  std::mt19937 rng(42);
  std::uniform_real_distribution<double> coord(0, 12), size(1, 6), zpos(0, 3);
  std::uniform_int_distribution<int> count(2, 7);
  int overlapping_sections = 0;
  for (int trial = 0; trial < 60; ++trial) {
    struct B {
      Eigen::Vector3d lo, hi;
    };
    std::vector<B> boxes;
    TriangleSoup soup;
    const int n = count(rng);
    while (static_cast<int>(boxes.size()) < n) {
      B b;
      b.lo = Eigen::Vector3d(coord(rng), coord(rng), zpos(rng));
      b.hi = b.lo + Eigen::Vector3d(size(rng), size(rng), size(rng));
      bool nested = false;
      for (const B& o : boxes)
        nested |= (o.lo.array() <= b.lo.array()).all() && (b.hi.array() <= o.hi.array()).all();
      for (const B& o : boxes)
        nested |= (b.lo.array() <= o.lo.array()).all() && (o.hi.array() <= b.hi.array()).all();
      if (nested) continue;
      boxes.push_back(b);
      soup = mesh_test::append(soup, mesh_test::box(b.lo.cast<float>(), b.hi.cast<float>()));
    }
    auto mesh = build_mesh(soup, MeshParams{});
    ASSERT_TRUE(mesh.has_value()) << mesh.error().message;
    double zmin = 1e9;
    for (const auto& c : soup.corners) zmin = std::min(zmin, static_cast<double>(c.z()));
    std::vector<double> zs;
    for (int k = 0; k < 12; ++k) zs.push_back(0.37 + 0.7 * k);
    auto slices = slice_mesh(*mesh, zs, SliceParams{});
    ASSERT_TRUE(slices.has_value());
    for (std::size_t k = 0; k < zs.size(); ++k) {
      const double z = zs[k] + zmin;  // back to the boxes' frame
      std::vector<std::array<double, 4>> rects;
      for (const B& b : boxes) {
        const Eigen::Vector3f lo = b.lo.cast<float>(), hi = b.hi.cast<float>();  // as stored
        if (lo.z() < z && z < hi.z()) rects.push_back({lo.x(), lo.y(), hi.x(), hi.y()});
      }
      const Slice& s = (*slices)[k];
      SCOPED_TRACE(::testing::Message() << "trial " << trial << " z " << z);
      const double want = union_area(rects);
      EXPECT_NEAR(s.net_area_mm2(), want, 1e-6 * std::max(1.0, want));
      EXPECT_TRUE(s.open_chains.empty());
      overlapping_sections += s.warnings.empty() ? 0 : 1;
      for (const Loop& l : s.loops) {
        EXPECT_EQ(l.depth % 2 == 1, l.is_hole()) << "orientation follows nesting";
        for (const std::int32_t f : l.facets) EXPECT_GE(f, 0) << "union pieces keep their facets";
      }
    }
  }
  EXPECT_GT(overlapping_sections, 100) << "the test must exercise the union";
}

// The same on an integer grid: bodies touching face to face, flush walls, shared edges. At a
// half-integer height the union's area is the number of unit cells covered, exactly.
TEST(SliceRobustness, UnionOfGridBoxesTouchingFaceToFaceMatchesTheRaster) {
  std::mt19937 rng(42);
  std::uniform_int_distribution<int> coord(0, 12), size(1, 6), count(2, 7);
  for (int trial = 0; trial < 150; ++trial) {
    struct B {
      int lo[3], hi[3];
    };
    std::vector<B> boxes;
    TriangleSoup soup;
    const int n = count(rng);
    while (static_cast<int>(boxes.size()) < n) {
      B b;
      for (int a = 0; a < 3; ++a) {
        b.lo[a] = a < 2 ? coord(rng) : coord(rng) % 4;
        b.hi[a] = b.lo[a] + size(rng);
      }
      bool nested = false;  // a shell wholly inside another is a cavity, not part of this test
      for (const B& o : boxes) {
        bool in1 = true, in2 = true;
        for (int a = 0; a < 3; ++a) {
          in1 &= o.lo[a] <= b.lo[a] && b.hi[a] <= o.hi[a];
          in2 &= b.lo[a] <= o.lo[a] && o.hi[a] <= b.hi[a];
        }
        nested |= in1 || in2;
      }
      if (nested) continue;
      boxes.push_back(b);
      soup = mesh_test::append(soup, mesh_test::box(Eigen::Vector3f(b.lo[0], b.lo[1], b.lo[2]),
                                                    Eigen::Vector3f(b.hi[0], b.hi[1], b.hi[2])));
    }
    auto mesh = build_mesh(soup, MeshParams{});
    ASSERT_TRUE(mesh.has_value()) << mesh.error().message;
    int zmin = 100;
    for (const B& b : boxes) zmin = std::min(zmin, b.lo[2]);
    std::vector<double> zs;
    for (int k = 0; k < 10; ++k) zs.push_back(k + 0.5);
    auto slices = slice_mesh(*mesh, zs, SliceParams{});
    ASSERT_TRUE(slices.has_value());
    for (std::size_t k = 0; k < zs.size(); ++k) {
      const double z = zs[k] + zmin;
      std::set<std::pair<int, int>> cells;
      for (const B& b : boxes)
        if (b.lo[2] < z && z < b.hi[2])
          for (int x = b.lo[0]; x < b.hi[0]; ++x)
            for (int y = b.lo[1]; y < b.hi[1]; ++y) cells.emplace(x, y);
      SCOPED_TRACE(::testing::Message() << "trial " << trial << " z " << z);
      EXPECT_NEAR((*slices)[k].net_area_mm2(), static_cast<double>(cells.size()), 1e-9);
    }
  }
}

// Triangles with corners on a coarse grid: on-plane vertices, shared and non-manifold edges,
// coincident and degenerate facets everywhere. Whatever build_mesh accepts must slice without
// crashing, into loops of at least three vectors with valid facets and finite areas.
TEST(SliceRobustness, RandomGridSoupsNeverBreakTheSlicer) {
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> c(0, 4), tris(1, 80);
  for (int trial = 0; trial < 400; ++trial) {
    TriangleSoup soup;
    const int n = tris(rng);
    for (int i = 0; i < 3 * n; ++i) soup.corners.emplace_back(c(rng), c(rng), c(rng));
    if (trial % 3 == 0) soup = mesh_test::append(soup, mesh_test::box({0, 0, 0}, {4, 4, 4}));
    auto mesh = build_mesh(soup, MeshParams{});
    if (!mesh) {
      EXPECT_EQ(mesh.error().code, ErrorCode::empty_mesh);
      continue;
    }
    std::vector<double> zs{0.0, 0.5, 1.0, 1.5, 2.0, 3.0, 4.0};
    SliceParams p;
    p.gap_close_mm = trial % 2 ? 0.0 : 2.0;
    auto slices = slice_mesh(*mesh, zs, p);
    ASSERT_TRUE(slices.has_value());
    for (const Slice& s : *slices)
      for (const Loop& l : s.loops) {
        EXPECT_GE(l.size(), 3u);
        EXPECT_TRUE(std::isfinite(l.area_mm2));
        for (const std::int32_t f : l.facets)
          EXPECT_TRUE(f == -1 || (f >= 0 && static_cast<std::size_t>(f) < mesh->faces.size()));
      }
  }
}

}  // namespace
}  // namespace lamina
