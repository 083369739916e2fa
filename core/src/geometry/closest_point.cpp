#include "geometry/closest_point.hpp"
#include "geometry/outward_float.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>
#include <tbb/parallel_sort.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

namespace lamina::geometry_detail {

namespace {

constexpr std::int32_t kLeafSize = 4;
// A hint that is not near enough: its neighbours in leaf order (Morton order of the centroids,
// so mostly its neighbours on the surface) are tried before a search from the root. On the 1M
// sphere's plan 58 % of the queries stopped at the hint, 81 % with four neighbours each side:
// the tree's nodes visited 65 M → 34 M.
constexpr std::int32_t kNearInLeafOrder = 4;

double segment_distance2(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  const Eigen::Vector3d ab = b - a;
  const double len2 = ab.squaredNorm();
  const double t = len2 > 0.0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
  return (a + t * ab - p).squaredNorm();
}

double box_distance2(const Eigen::Vector3d& p, const Eigen::Vector3f& lo, const Eigen::Vector3f& hi) {
  double d2 = 0.0;
  for (int k = 0; k < 3; ++k) {
    const double d = std::max({static_cast<double>(lo[k]) - p[k], 0.0, p[k] - static_cast<double>(hi[k])});
    d2 += d * d;
  }
  return d2;
}

// f(i) for every i < n, on the threads allowed (in blocks of 16k: each call is a few ns).
template <class F>
void for_each_index(std::size_t n, Threads threads, F&& f) {
  if (threads == Threads::one) {
    for (std::size_t i = 0; i < n; ++i) f(i);
    return;
  }
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 16384), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t i = r.begin(); i != r.end(); ++i) f(i);
  });
}

// Morton keys (21 bits per axis) of points over their bounding box.
std::vector<std::pair<std::uint64_t, std::uint32_t>> morton_keys(const std::vector<Eigen::Vector3d>& points,
                                                                 Threads threads) {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const auto& p : points) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const Eigen::Vector3d scale = ((1 << 21) - 1) / (hi - lo).cwiseMax(1e-300).array();
  auto spread = [](std::uint64_t v) {  // 21 bits → every third bit
    v &= 0x1fffffu;
    v = (v | v << 32) & 0x1f00000000ffffULL;
    v = (v | v << 16) & 0x1f0000ff0000ffULL;
    v = (v | v << 8) & 0x100f00f00f00f00fULL;
    v = (v | v << 4) & 0x10c30c30c30c30c3ULL;
    v = (v | v << 2) & 0x1249249249249249ULL;
    return v;
  };
  std::vector<std::pair<std::uint64_t, std::uint32_t>> keys(points.size());
  auto key = [&](std::size_t i) {
    const Eigen::Vector3d q = (points[i] - lo).cwiseProduct(scale);
    const auto x = static_cast<std::uint64_t>(std::clamp(q.x(), 0.0, 2097151.0));
    const auto y = static_cast<std::uint64_t>(std::clamp(q.y(), 0.0, 2097151.0));
    const auto z = static_cast<std::uint64_t>(std::clamp(q.z(), 0.0, 2097151.0));
    keys[i] = {spread(x) | spread(y) << 1 | spread(z) << 2, static_cast<std::uint32_t>(i)};
  };
  for_each_index(points.size(), threads, key);
  return keys;
}

void sort_keys(std::vector<std::pair<std::uint64_t, std::uint32_t>>& keys, Threads threads) {
  if (threads == Threads::many)
    tbb::parallel_sort(keys.begin(), keys.end());
  else
    std::sort(keys.begin(), keys.end());
}

// Nodes of a subtree over m triangles (median splits, so it depends on m only).
std::size_t subtree_nodes(std::size_t m, std::map<std::size_t, std::size_t>& memo) {
  if (m <= static_cast<std::size_t>(kLeafSize)) return 1;
  if (auto it = memo.find(m); it != memo.end()) return it->second;
  const std::size_t n = 1 + subtree_nodes(m / 2, memo) + subtree_nodes(m - m / 2, memo);
  memo.emplace(m, n);
  return n;
}

}  // namespace

double point_triangle_distance2(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                const Eigen::Vector3d& c) {
  const Eigen::Vector3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0.0 && d2 <= 0.0) return ap.squaredNorm();
  const Eigen::Vector3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0.0 && d4 <= d3) return bp.squaredNorm();
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) {
    const double v = d1 / (d1 - d3);
    return (a + v * ab - p).squaredNorm();
  }
  const Eigen::Vector3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0.0 && d5 <= d6) return cp.squaredNorm();
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) {
    const double w = d2 / (d2 - d6);
    return (a + w * ac - p).squaredNorm();
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) {
    const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return (b + w * (c - b) - p).squaredNorm();
  }
  const double denom = va + vb + vc;
  if (!(denom > 0.0) || !std::isfinite(denom)) {
    // No area (or a numerically flat triangle): its edges are the triangle.
    return std::min({segment_distance2(p, a, b), segment_distance2(p, b, c), segment_distance2(p, c, a)});
  }
  const double v = vb / denom, w = vc / denom;
  return (a + v * ab + w * ac - p).squaredNorm();
}

TriangleTree::TriangleTree(const std::vector<Eigen::Vector3d>& vertices,
                           const std::vector<std::array<std::int32_t, 3>>& faces, Threads threads) {
  const std::size_t n = faces.size();
  if (n == 0) return;
  // Triangles in Morton order of their centroids (21 bits per axis over the centroids' box); the
  // tree halves that order (median splits, so its layout depends on the count only) and takes
  // its boxes bottom-up. Building is a sort: 4× faster than a median split per node on the
  // longest axis (40 vs 160 ms for 360k triangles), and queries measured as fast.
  std::vector<Eigen::Vector3d> centroid(n);
  for (std::size_t f = 0; f < n; ++f)
    centroid[f] = (vertices[static_cast<std::size_t>(faces[f][0])] + vertices[static_cast<std::size_t>(faces[f][1])] +
                   vertices[static_cast<std::size_t>(faces[f][2])]) /
                  3.0;
  auto keys = morton_keys(centroid, threads);
  std::vector<Eigen::Vector3d>().swap(centroid);  // not held while the rest is built (peak memory)
  sort_keys(keys, threads);

  tris_.resize(n);
  std::vector<std::int32_t> renumbered(vertices.size(), -1);
  verts_.reserve(std::min(vertices.size(), 3 * n));
  for (std::size_t i = 0; i < n; ++i) {
    const auto& f = faces[static_cast<std::size_t>(keys[i].second)];
    for (std::size_t k = 0; k < 3; ++k) {
      std::int32_t& v = renumbered[static_cast<std::size_t>(f[k])];
      if (v < 0) {
        v = static_cast<std::int32_t>(verts_.size());
        verts_.push_back(vertices[static_cast<std::size_t>(f[k])]);
      }
      tris_[i][k] = v;
    }
  }
  std::vector<std::int32_t>().swap(renumbered);
  decltype(keys)().swap(keys);

  std::map<std::size_t, std::size_t> memo;
  nodes_.resize(subtree_nodes(n, memo));
  auto build = [&](auto&& self, std::size_t node, std::size_t begin, std::size_t end) -> void {
    Node& nd = nodes_[node];
    const std::size_t m = end - begin;
    if (m <= static_cast<std::size_t>(kLeafSize)) {
      Eigen::Vector3d lo = verts_[static_cast<std::size_t>(tris_[begin][0])], hi = lo;
      for (std::size_t i = begin; i < end; ++i)
        for (const std::int32_t v : tris_[i]) {
          lo = lo.cwiseMin(verts_[static_cast<std::size_t>(v)]);
          hi = hi.cwiseMax(verts_[static_cast<std::size_t>(v)]);
        }
      for (int k = 0; k < 3; ++k) {
        nd.lo[k] = float_at_most(lo[k]);
        nd.hi[k] = float_at_least(hi[k]);
      }
      nd.first = static_cast<std::int32_t>(begin);
      nd.count = static_cast<std::int32_t>(m);
      return;
    }
    const std::size_t mid = begin + m / 2;
    const std::size_t left = node + 1;
    const std::size_t right = left + subtree_nodes(m / 2, memo);
    if (threads == Threads::many && m > 50000) {
      tbb::parallel_invoke([&] { self(self, left, begin, mid); }, [&] { self(self, right, mid, end); });
    } else {
      self(self, left, begin, mid);
      self(self, right, mid, end);
    }
    nd.lo = nodes_[left].lo.cwiseMin(nodes_[right].lo);
    nd.hi = nodes_[left].hi.cwiseMax(nodes_[right].hi);
    nd.first = static_cast<std::int32_t>(right);
    nd.count = 0;
  };
  // The sizing pass above filled the memo for every subtree size the build asks for, so the
  // (parallel) build only reads it.
  build(build, 0, 0, n);
}

void sort_morton(std::vector<Eigen::Vector3d>& points, Threads threads) {
  auto keys = morton_keys(points, threads);
  sort_keys(keys, threads);
  std::vector<Eigen::Vector3d> sorted(points.size());
  auto gather = [&](std::size_t i) { sorted[i] = points[keys[i].second]; };
  for_each_index(points.size(), threads, gather);
  points = std::move(sorted);
}

double TriangleTree::distance(const Eigen::Vector3d& p, double enough, std::int32_t& hint) const {
  if (tris_.empty()) return std::numeric_limits<double>::infinity();
  const double enough2 = enough > 0.0 ? enough * enough : 0.0;
  double best2 = std::numeric_limits<double>::infinity();
  if (hint >= 0 && static_cast<std::size_t>(hint) < tris_.size()) {
    best2 = distance2_to(static_cast<std::size_t>(hint), p);
    if (best2 <= enough2) return std::sqrt(best2);
    const std::int32_t lo = std::max<std::int32_t>(0, hint - kNearInLeafOrder);
    const std::int32_t hi = std::min<std::int32_t>(static_cast<std::int32_t>(tris_.size()) - 1, hint + kNearInLeafOrder);
    const std::int32_t given = hint;
    for (std::int32_t i = lo; i <= hi; ++i) {
      if (i == given) continue;
      const double d2 = distance2_to(static_cast<std::size_t>(i), p);
      if (d2 < best2) {
        best2 = d2;
        hint = i;
        if (best2 <= enough2) return std::sqrt(best2);
      }
    }
  }
  struct Entry {
    std::int32_t node;
    double d2;
  };
  Entry stack[96];
  int top = 0;
  stack[top++] = {0, box_distance2(p, nodes_[0].lo, nodes_[0].hi)};
  while (top > 0) {
    const Entry e = stack[--top];
    if (e.d2 >= best2) continue;
    const Node& nd = nodes_[static_cast<std::size_t>(e.node)];
    if (nd.count > 0) {
      for (std::int32_t i = nd.first; i < nd.first + nd.count; ++i) {
        const double d2 = distance2_to(static_cast<std::size_t>(i), p);
        if (d2 < best2) {
          best2 = d2;
          hint = i;
          if (best2 <= enough2) return std::sqrt(best2);
        }
      }
      continue;
    }
    const std::int32_t l = e.node + 1, r = nd.first;
    const double dl = box_distance2(p, nodes_[static_cast<std::size_t>(l)].lo, nodes_[static_cast<std::size_t>(l)].hi);
    const double dr = box_distance2(p, nodes_[static_cast<std::size_t>(r)].lo, nodes_[static_cast<std::size_t>(r)].hi);
    // Nearer child on top of the stack.
    if (dl <= dr) {
      if (dr < best2) stack[top++] = {r, dr};
      if (dl < best2) stack[top++] = {l, dl};
    } else {
      if (dl < best2) stack[top++] = {l, dl};
      if (dr < best2) stack[top++] = {r, dr};
    }
  }
  return std::sqrt(best2);
}

}  // namespace lamina::geometry_detail
