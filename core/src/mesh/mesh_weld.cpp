// Steps 1–2 of build_mesh: drop non-finite facets, weld, put the points in the build frame.
//
// One pass over the corners does both welds. Points are hashed by the cell of a grid whose
// cells are much larger than the weld tolerance, into an open-addressing table whose slots hold
// the point's bit pattern, so a corner repeating a known point (most corners) costs one memory
// access, prefetched a few corners ahead.
//  - exact weld: a corner bit-identical to a point already seen (+0 and -0 alike) is that point;
//  - tolerance weld: a new point is compared with the points before it in its own cell and, only
//    when it lies within tolerance of a cell face, in the neighbour cell(s) across that face
//    (every close pair is seen once, by its later point); close points are merged with
//    union-find, the lowest index (first appearance) being the representative.
// The grid works in file units; only the distinct points are converted to the build frame.
#include "mesh/mesh_internal.hpp"

#include <Eigen/Geometry>

#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

namespace lamina::mesh_detail {
namespace {

using Key = std::array<std::uint32_t, 3>;

// The bit pattern of a corner, with -0 read as +0 (equal values, one vertex).
inline Key key_of(const Eigen::Vector3f& c) {
  const Eigen::Vector3f p = c.array() + 0.0f;
  Key k;
  std::memcpy(k.data(), p.data(), sizeof k);
  return k;
}

// No NaN or infinite coordinate (exponent bits not all ones).
inline bool finite(const Key& k) {
  constexpr std::uint32_t exp = 0x7f800000u;
  return ((k[0] & exp) != exp) & ((k[1] & exp) != exp) & ((k[2] & exp) != exp);
}

inline bool same(const Key& a, const Key& b) { return ((a[0] ^ b[0]) | (a[1] ^ b[1]) | (a[2] ^ b[2])) == 0; }

inline std::uint64_t hash_cell(std::int64_t x, std::int64_t y, std::int64_t z) {
  std::uint64_t h = static_cast<std::uint64_t>(x) * 0x9E3779B97F4A7C15ULL;
  h ^= static_cast<std::uint64_t>(y) * 0xC2B2AE3D27D4EB4FULL + (h << 6) + (h >> 2);
  h ^= static_cast<std::uint64_t>(z) * 0x165667B19E3779F9ULL + (h << 6) + (h >> 2);
  return mix64(h);
}

constexpr std::size_t kAhead = 16;  // prefetch distance (corners)

struct Grid {
  Eigen::Vector3d lo;
  double inv_cell = 1.0;
  // Cell coordinates of p, and p's position inside the cell (0..1) per axis. p is inside the
  // box, so q >= 0 and truncation is floor (std::floor is a library call on baseline x86-64).
  std::array<std::int64_t, 3> cell(const Eigen::Vector3d& p, double frac[3]) const {
    std::array<std::int64_t, 3> c;
    for (int a = 0; a < 3; ++a) {
      const double q = std::max(0.0, (p[a] - lo[a]) * inv_cell);
      const auto i = static_cast<std::int64_t>(q);
      frac[a] = q - static_cast<double>(i);
      c[static_cast<std::size_t>(a)] = i;
    }
    return c;
  }
  std::uint64_t hash(const Eigen::Vector3d& p) const {
    double frac[3];
    const auto c = cell(p, frac);
    return hash_cell(c[0], c[1], c[2]);
  }
};

struct Slot {
  Key k;            // the point's bit pattern: identity and position
  std::int32_t id;  // -1: empty
};

struct UnionFind {
  std::vector<std::int32_t> parent;
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

struct Bounds {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d hi = Eigen::Vector3d::Constant(-std::numeric_limits<double>::infinity());
  std::size_t bad = 0;
  std::size_t first_bad = std::numeric_limits<std::size_t>::max();
};

// Box of the finite facets' corners (file units) and the non-finite facets. Parallel; min, max,
// count and first index do not depend on the split.
Bounds scan(const TriangleSoup& soup) {
  const std::size_t nf = soup.triangle_count();
  return tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, nf, 1 << 15), Bounds{},
      [&](const tbb::blocked_range<std::size_t>& r, Bounds b) {
        // One accumulator per corner position: three independent min/max chains per facet.
        Eigen::Vector3f lo[3], hi[3];
        for (int k = 0; k < 3; ++k) lo[k] = b.lo.cast<float>(), hi[k] = b.hi.cast<float>();
        for (std::size_t f = r.begin(); f != r.end(); ++f) {
          const Eigen::Vector3f& p0 = soup.corners[3 * f];
          const Eigen::Vector3f& p1 = soup.corners[3 * f + 1];
          const Eigen::Vector3f& p2 = soup.corners[3 * f + 2];
          if (!(finite(key_of(p0)) & finite(key_of(p1)) & finite(key_of(p2)))) {
            b.first_bad = std::min(b.first_bad, f);
            ++b.bad;
            continue;
          }
          lo[0] = lo[0].cwiseMin(p0), lo[1] = lo[1].cwiseMin(p1), lo[2] = lo[2].cwiseMin(p2);
          hi[0] = hi[0].cwiseMax(p0), hi[1] = hi[1].cwiseMax(p1), hi[2] = hi[2].cwiseMax(p2);
        }
        b.lo = lo[0].cwiseMin(lo[1]).cwiseMin(lo[2]).cast<double>();
        b.hi = hi[0].cwiseMax(hi[1]).cwiseMax(hi[2]).cast<double>();
        return b;
      },
      [](Bounds a, const Bounds& b) {
        a.lo = a.lo.cwiseMin(b.lo);
        a.hi = a.hi.cwiseMax(b.hi);
        a.bad += b.bad;
        a.first_bad = std::min(a.first_bad, b.first_bad);
        return a;
      });
}

}  // namespace

}  // namespace lamina::mesh_detail

namespace lamina {

Eigen::Matrix3d build_frame_rotation(const MeshParams& params) {
  Eigen::Matrix3d r;
  if (params.direction) {
    r = Eigen::Quaterniond::FromTwoVectors(*params.direction, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    return r;
  }
  switch (params.axis) {
    case BuildAxis::x: r << 0, 1, 0, 0, 0, 1, 1, 0, 0; return r;  // (x,y,z) → (y,z,x): +X becomes +Z
    case BuildAxis::y: r << 0, 0, 1, 1, 0, 0, 0, 1, 0; return r;  // (x,y,z) → (z,x,y): +Y becomes +Z
    case BuildAxis::z: break;
  }
  return Eigen::Matrix3d::Identity();
}

}  // namespace lamina

namespace lamina::mesh_detail {

Eigen::Vector3d to_build_frame(const Eigen::Vector3d& p, const Eigen::Matrix3d& rotation, double scale) {
  // Permutation matrices multiply exactly (0·a + 1·b + 0·c == b for finite values).
  return (rotation * p) * scale;
}

namespace {

Eigen::Vector3d point_of(const Key& k) {
  Eigen::Vector3f p;
  std::memcpy(p.data(), k.data(), sizeof k);
  return Eigen::Vector3d(p.cast<double>());
}

// The distinct points of a soup, welded exactly (same float bits) through an open-addressing
// table on the cell hash, and within `tol` through a union-find over neighbouring cells.
//
// Open addressing on the cell hash: a point sits in the probe run that starts at its cell's
// slot, so the points of one cell (and, rarely, of cells hashing nearby) are contiguous, and the
// bit pattern in the slot gives both identity and position. A closed mesh has about one point per
// six corners: start at load <= 0.5 for that and double past 0.5.
struct PointTable {
  Grid grid;
  double tol2 = 0.0;
  double near = -1.0;  // in cell units; < 0: exact weld only
  std::vector<Key> keys;  // the distinct points, in order of first appearance
  UnionFind uf;
  std::size_t cap = 0, mask = 0;
  std::vector<Slot> table;

  void make_table() {
    table = {};
    table.reserve(cap);
    hint_huge_pages(table.data(), cap * sizeof(Slot));
    table.assign(cap, Slot{{0, 0, 0}, -1});
  }
  void grow() {
    cap <<= 1;
    mask = cap - 1;
    make_table();
    for (std::size_t i = 0; i < keys.size(); ++i) {
      std::size_t s = grid.hash(point_of(keys[i])) & mask;
      while (table[s].id >= 0) s = (s + 1) & mask;
      table[s] = Slot{keys[i], static_cast<std::int32_t>(i)};
    }
  }
  // The id of k in the run starting at h; -1 and `free_slot` where it would go when new.
  std::int32_t find(const Key& k, std::uint64_t h, std::size_t& free_slot) const {
    std::size_t s = h & mask;
    for (; table[s].id >= 0; s = (s + 1) & mask)
      if (same(table[s].k, k)) return table[s].id;
    free_slot = s;
    return -1;
  }
  // Unites point i with every point within tol: its own cell's run and the neighbouring cells
  // it lies within `near` of.
  void unite_near(std::int32_t i, const Eigen::Vector3d& p, std::uint64_t h) {
    auto visit = [&](std::size_t t) {
      for (; table[t].id >= 0; t = (t + 1) & mask)
        if ((point_of(table[t].k) - p).squaredNorm() <= tol2) uf.unite(i, table[t].id);
    };
    visit(h & mask);
    double frac[3];
    const auto c0 = grid.cell(p, frac);
    std::int64_t cs[3][2];
    int cn[3];
    for (int a = 0; a < 3; ++a) {
      cs[a][0] = c0[static_cast<std::size_t>(a)];
      cn[a] = 1;
      if (frac[a] < near)
        cs[a][cn[a]++] = cs[a][0] - 1;
      else if (frac[a] > 1.0 - near)
        cs[a][cn[a]++] = cs[a][0] + 1;
    }
    if (cn[0] + cn[1] + cn[2] <= 3) return;
    for (int ix = 0; ix < cn[0]; ++ix)
      for (int iy = 0; iy < cn[1]; ++iy)
        for (int iz = 0; iz < cn[2]; ++iz)
          if (ix + iy + iz > 0) visit(hash_cell(cs[0][ix], cs[1][iy], cs[2][iz]) & mask);
  }
  // A new point at `free_slot`; its id.
  std::int32_t add(const Key& k, const Eigen::Vector3d& p, std::uint64_t h, std::size_t free_slot) {
    const auto i = static_cast<std::int32_t>(keys.size());
    keys.push_back(k);
    uf.parent.push_back(i);
    if (near >= 0.0) unite_near(i, p, h);
    table[free_slot] = Slot{k, i};
    if (keys.size() * 2 > cap) grow();
    return i;
  }
};

// The grid, in file units. Cells far larger than the tolerance, so a point is rarely near a
// face; the floor keeps cell indices well inside int64 for absurdly small tolerances.
PointTable make_point_table(const Bounds& bounds, double tol, std::size_t corners) {
  PointTable t;
  const double diag = (bounds.hi - bounds.lo).norm();
  const bool tolerant = tol > 0.0;
  t.tol2 = tol * tol;
  t.grid.lo = bounds.lo;
  const double cell = diag > 0.0 ? std::max(tolerant ? tol * 64.0 : diag * 1e-5, diag * 1e-12) : 1.0;
  t.grid.inv_cell = 1.0 / cell;
  t.near = tolerant ? tol * t.grid.inv_cell * (1.0 + 1e-9) + 1e-12 : -1.0;
  const std::size_t guess = corners / 5 + 16;
  t.keys.reserve(guess);
  t.uf.parent.reserve(guess);
  t.cap = pow2_at_least(corners / 3 + 1);
  t.mask = t.cap - 1;
  t.make_table();
  return t;
}

// Every corner's point id (-1 for a facet with a non-finite corner).
void weld_corners(const TriangleSoup& soup, PointTable& t, std::vector<std::int32_t>& corner_point) {
  const std::size_t nc = soup.triangle_count() * 3;
  auto corner_hash = [&](std::size_t c) { return t.grid.hash(soup.corners[c].cast<double>()); };
  // Neighbouring facets of a file share corners a few facets apart: a small cache of recent
  // points answers most repeats without touching the big table (a cache miss each).
  constexpr std::size_t kRecent = 1 << 14;
  std::vector<Slot> recent(kRecent, Slot{{0, 0, 0}, -1});
  bool facet_ok = true;
  std::uint64_t ring[kAhead];
  for (std::size_t c = 0; c < std::min(nc, kAhead); ++c) ring[c] = corner_hash(c);
  for (std::size_t c = 0; c < nc; ++c) {
    const std::uint64_t h = ring[c % kAhead];
    if (c + kAhead < nc) {
      const std::uint64_t ha = corner_hash(c + kAhead);
      ring[c % kAhead] = ha;
      __builtin_prefetch(&t.table[ha & t.mask]);
    }
    if (c % 3 == 0)
      facet_ok = finite(key_of(soup.corners[c])) && finite(key_of(soup.corners[c + 1])) &&
                 finite(key_of(soup.corners[c + 2]));
    if (!facet_ok) {
      corner_point[c] = -1;
      continue;
    }
    const Key k = key_of(soup.corners[c]);
    Slot& cached = recent[(h ^ (h >> 17)) & (kRecent - 1)];
    if (cached.id >= 0 && same(cached.k, k)) {
      corner_point[c] = cached.id;
      continue;
    }
    std::size_t free_slot = 0;
    std::int32_t id = t.find(k, h, free_slot);
    if (id < 0) id = t.add(k, soup.corners[c].cast<double>(), h, free_slot);
    cached = Slot{k, id};
    corner_point[c] = id;
  }
}

}  // namespace

WeldResult weld_soup(const TriangleSoup& soup, const MeshParams& params) {
  WeldResult w;
  const std::size_t nf = soup.triangle_count();
  const std::size_t nc = nf * 3;

  const Bounds bounds = scan(soup);
  w.nan_facets = bounds.bad;
  w.first_nan_facet = bounds.bad > 0 ? bounds.first_bad : 0;
  w.corner_point.resize(nc);
  if (bounds.bad == nf) {
    std::fill(w.corner_point.begin(), w.corner_point.end(), -1);
    return w;
  }
  const double tol = params.weld_tolerance_rel * (bounds.hi - bounds.lo).norm();
  PointTable t = make_point_table(bounds, tol, nc);
  weld_corners(soup, t, w.corner_point);
  t.table = {};

  // Representatives, the weld report, and the build frame.
  const std::size_t n = t.keys.size();
  w.rep.resize(n);
  w.points.resize(n);
  const Eigen::Matrix3d rotation = build_frame_rotation(params);
  for (std::size_t i = 0; i < n; ++i) {
    w.points[i] = to_build_frame(point_of(t.keys[i]), rotation, params.scale_to_mm);
    const std::int32_t r = t.uf.find(static_cast<std::int32_t>(i));
    w.rep[i] = r;
    if (r != static_cast<std::int32_t>(i)) {
      if (w.tolerance_merged == 0) w.first_merged = w.points[i];
      ++w.tolerance_merged;
    }
  }
  w.tolerance = tol * params.scale_to_mm;
  return w;
}

}  // namespace lamina::mesh_detail
