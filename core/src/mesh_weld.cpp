// Step 1–2 of build_mesh: into the build frame, weld.
//
// After the exact weld (mesh_weld_exact.cpp) only unique points are converted to double and
// put in the build frame. The tolerance weld then runs once over those unique points with a hashed grid whose cells are much larger than the
// tolerance: each point looks only into its own cell, plus a neighbour cell across a face it
// lies within tolerance of, against the points inserted before it (so every close pair is
// seen once, by its later point), and merges with union-find (the lowest index is the root).
#include "mesh_internal.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>

namespace lamina::mesh_detail {
namespace {

inline std::uint64_t hash_cell(std::int64_t x, std::int64_t y, std::int64_t z) {
  std::uint64_t h = static_cast<std::uint64_t>(x) * 0x9E3779B97F4A7C15ULL;
  h ^= static_cast<std::uint64_t>(y) * 0xC2B2AE3D27D4EB4FULL + (h << 6) + (h >> 2);
  h ^= static_cast<std::uint64_t>(z) * 0x165667B19E3779F9ULL + (h << 6) + (h >> 2);
  return mix64(h);
}

// Lookahead of the software prefetch: the cell table is far larger than the caches.
constexpr std::size_t kAhead = 16;

struct UnionFind {
  std::vector<std::int32_t> parent;
  explicit UnionFind(std::size_t n) : parent(n) {
    for (std::size_t i = 0; i < n; ++i) parent[i] = static_cast<std::int32_t>(i);
  }
  std::int32_t find(std::int32_t x) {
    while (parent[static_cast<std::size_t>(x)] != x) {
      auto& p = parent[static_cast<std::size_t>(x)];
      p = parent[static_cast<std::size_t>(p)];  // path halving
      x = p;
    }
    return x;
  }
  void unite(std::int32_t a, std::int32_t b) {
    a = find(a);
    b = find(b);
    if (a == b) return;
    if (a < b) std::swap(a, b);
    parent[static_cast<std::size_t>(a)] = b;  // the lower index stays the root
  }
};

// Tolerance weld of the (exactly unique) points; fills rep.
void tolerance_weld(WeldResult& w) {
  const std::size_t n = w.points.size();
  w.rep.resize(n);
  for (std::size_t i = 0; i < n; ++i) w.rep[i] = static_cast<std::int32_t>(i);
  const double tol = w.tolerance;
  if (!(tol > 0.0) || n < 2) return;

  const double diag = (w.bbox_max - w.bbox_min).norm();
  // Cells far larger than the tolerance: a point is rarely near a cell face. The floor keeps
  // cell indices well inside int64 for absurdly small tolerances.
  const double cell = std::max(tol * 64.0, diag * 1e-12);
  const double inv_cell = 1.0 / cell;
  const double near = tol * inv_cell * (1.0 + 1e-9) + 1e-12;  // in cell units, conservative
  const double tol2 = tol * tol;

  struct Slot {
    std::uint32_t tag;  // upper bits of the cell hash; cells sharing a tag share a list (harmless)
    std::int32_t head;  // -1: empty
  };
  const std::size_t cap = pow2_at_least(2 * n);
  const std::size_t mask = cap - 1;
  std::vector<Slot> table(cap, Slot{0, -1});
  std::vector<std::int32_t> next(n, -1);
  UnionFind uf(n);

  auto find_slot = [&](std::uint64_t key) -> std::size_t {
    const auto tag = static_cast<std::uint32_t>(key >> 32);
    std::size_t s = key & mask;
    while (table[s].head >= 0 && table[s].tag != tag) s = (s + 1) & mask;
    return s;
  };
  auto own_cell = [&](std::size_t i, double fr[3]) {
    const Eigen::Vector3d q = (w.points[i] - w.bbox_min) * inv_cell;
    std::array<std::int64_t, 3> c;
    for (int a = 0; a < 3; ++a) {
      const double fl = std::floor(q[a]);
      fr[a] = q[a] - fl;
      c[static_cast<std::size_t>(a)] = static_cast<std::int64_t>(fl);
    }
    return c;
  };

  std::uint64_t ring[kAhead];
  for (std::size_t i = 0; i < std::min(n, kAhead); ++i) {
    double fr[3];
    const auto c = own_cell(i, fr);
    ring[i] = hash_cell(c[0], c[1], c[2]);
    __builtin_prefetch(&table[ring[i] & mask]);
  }
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint64_t own_key = ring[i % kAhead];
    if (i + kAhead < n) {
      double fr[3];
      const auto c = own_cell(i + kAhead, fr);
      ring[i % kAhead] = hash_cell(c[0], c[1], c[2]);
      __builtin_prefetch(&table[ring[i % kAhead] & mask]);
    }
    const Eigen::Vector3d& p = w.points[i];
    double fr[3];
    const auto c0 = own_cell(i, fr);
    std::int64_t c[3][2];
    int cn[3];
    for (int a = 0; a < 3; ++a) {
      c[a][0] = c0[static_cast<std::size_t>(a)];
      cn[a] = 1;
      if (fr[a] < near) {
        c[a][cn[a]++] = c[a][0] - 1;
      } else if (fr[a] > 1.0 - near) {
        c[a][cn[a]++] = c[a][0] + 1;
      }
    }
    auto visit = [&](std::size_t s) {
      for (std::int32_t j = table[s].head; j >= 0; j = next[static_cast<std::size_t>(j)]) {
        if ((w.points[static_cast<std::size_t>(j)] - p).squaredNorm() <= tol2) uf.unite(static_cast<std::int32_t>(i), j);
      }
    };
    const std::size_t own_slot = find_slot(own_key);
    visit(own_slot);
    if (cn[0] + cn[1] + cn[2] > 3) {
      for (int ix = 0; ix < cn[0]; ++ix)
        for (int iy = 0; iy < cn[1]; ++iy)
          for (int iz = 0; iz < cn[2]; ++iz)
            if (ix + iy + iz > 0) visit(find_slot(hash_cell(c[0][ix], c[1][iy], c[2][iz])));
    }
    if (table[own_slot].head < 0) table[own_slot].tag = static_cast<std::uint32_t>(own_key >> 32);
    next[i] = table[own_slot].head;
    table[own_slot].head = static_cast<std::int32_t>(i);
  }

  for (std::size_t i = 0; i < n; ++i) {
    const std::int32_t r = uf.find(static_cast<std::int32_t>(i));
    w.rep[i] = r;
    if (r != static_cast<std::int32_t>(i)) {
      if (w.tolerance_merged == 0) w.first_merged = w.points[i];
      ++w.tolerance_merged;
    }
  }
}

}  // namespace

Eigen::Vector3d to_build_frame(const Eigen::Vector3f& p, BuildAxis axis, double scale) {
  const double x = p.x(), y = p.y(), z = p.z();
  switch (axis) {
    case BuildAxis::x: return Eigen::Vector3d(y, z, x) * scale;  // +X becomes +Z
    case BuildAxis::y: return Eigen::Vector3d(z, x, y) * scale;  // +Y becomes +Z
    case BuildAxis::z: break;
  }
  return Eigen::Vector3d(x, y, z) * scale;
}

WeldResult weld_soup(const TriangleSoup& soup, const MeshParams& params) {
  WeldResult w;
  LAMINA_TIMER();
  ExactWeld ex = exact_weld(soup);
  LAMINA_TICK("w:exact");
  w.nan_facets = ex.nan_facets;
  w.first_nan_facet = ex.first_nan_facet;
  w.corner_point = std::move(ex.corner_point);

  w.points.resize(ex.keys.size());
  for (std::size_t i = 0; i < ex.keys.size(); ++i) {
    Eigen::Vector3f p;
    std::memcpy(p.data(), ex.keys[i].data(), sizeof ex.keys[i]);
    w.points[i] = to_build_frame(p, params.axis, params.scale_to_mm);
  }
  ex.keys = {};
  if (!w.points.empty()) {
    w.bbox_min = w.bbox_max = w.points[0];
    for (const auto& p : w.points) {
      w.bbox_min = w.bbox_min.cwiseMin(p);
      w.bbox_max = w.bbox_max.cwiseMax(p);
    }
  }
  w.tolerance = params.weld_tolerance_rel * (w.bbox_max - w.bbox_min).norm();
  LAMINA_TICK("w:frame");
  tolerance_weld(w);
  LAMINA_TICK("w:tolerance");
  return w;
}

}  // namespace lamina::mesh_detail
