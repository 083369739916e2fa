// Ear clipping of a 3D polygon in its Newell-normal plane, then a flip pass that removes the
// zero-area slivers left by corners lying on a straight edge.
//
// Faces below kLargeFace corners (what CAD exporters write, cylinder caps included) are cut by
// the walk below, which tests each ear against every corner, exactly as before; larger ones by
// triangulate_polygon_with_holes, whose ear tests look only at reflex corners near the ear: the
// walk costs n² tests or more (60 s for one 100,000-corner face), the other about n log n.
#include "geometry/ear_clipping.hpp"

#include "geometry/polygon_triangulation.hpp"

#include <Eigen/Geometry>

#include <cmath>
#include <limits>
#include <unordered_map>

namespace lamina::geometry_detail {
namespace {

void fan(std::uint32_t n, std::vector<std::array<std::uint32_t, 3>>& out) {
  for (std::uint32_t i = 1; i + 1 < n; ++i) out.push_back({0, i, i + 1});
}

// Corners turning by less than this angle (its sine) count as straight: float input rounds the
// collinear corners of a tilted polygon to turns of ~1e-7 either way.
constexpr double kStraightSine = 1e-5;
// Faces from this many corners go to the indexed clipper.
constexpr std::uint32_t kLargeFace = 64;

// The polygon's corners in its plane (scratch.x, scratch.y), counter-clockwise.
struct Plane {
  const EarClippingScratch& s;

  double cross(std::uint32_t a, std::uint32_t b, std::uint32_t c) const {
    return (s.x[b] - s.x[a]) * (s.y[c] - s.y[b]) - (s.y[b] - s.y[a]) * (s.x[c] - s.x[b]);
  }
  double length2(std::uint32_t a, std::uint32_t b) const {
    const double dx = s.x[b] - s.x[a], dy = s.y[b] - s.y[a];
    return dx * dx + dy * dy;
  }
  // |turn at b| ≤ kStraightSine · |ab| · |bc|, compared squared.
  bool straight(std::uint32_t a, std::uint32_t b, std::uint32_t c) const {
    const double turn = cross(a, b, c);
    return turn * turn <= kStraightSine * kStraightSine * length2(a, b) * length2(b, c);
  }
  bool convex(std::uint32_t a, std::uint32_t b, std::uint32_t c) const { return cross(a, b, c) > 0.0 && !straight(a, b, c); }
  bool same_point(std::uint32_t a, std::uint32_t b) const { return s.x[a] == s.x[b] && s.y[a] == s.y[b]; }
  // Point r inside or on triangle (a, b, c), which is counter-clockwise.
  bool inside(std::uint32_t r, std::uint32_t a, std::uint32_t b, std::uint32_t c) const {
    const auto side = [this, r](std::uint32_t p, std::uint32_t q) {
      return (s.x[q] - s.x[p]) * (s.y[r] - s.y[p]) - (s.y[q] - s.y[p]) * (s.x[r] - s.x[p]);
    };
    return side(a, b) >= 0.0 && side(b, c) >= 0.0 && side(c, a) >= 0.0;
  }
  // Triangle t = (a, m, b) = (t[k], t[k+1], t[k+2]) has no area, m lying strictly between a and b.
  bool sliver_at(const std::array<std::uint32_t, 3>& t, int k) const {
    const std::uint32_t a = t[k], m = t[(k + 1) % 3], b = t[(k + 2) % 3];
    return straight(a, m, b) && (s.x[m] - s.x[a]) * (s.x[b] - s.x[m]) + (s.y[m] - s.y[a]) * (s.y[b] - s.y[m]) > 0.0;
  }
  bool sliver(const std::array<std::uint32_t, 3>& t) const { return sliver_at(t, 0) || sliver_at(t, 1) || sliver_at(t, 2); }
};

// Newell normal (unit) and centroid, in double; false when the polygon has no area (or NaN corners).
bool plane_of(std::span<const Eigen::Vector3f> corners, Eigen::Vector3d& normal, Eigen::Vector3d& centroid) {
  const auto n = static_cast<std::uint32_t>(corners.size());
  normal = Eigen::Vector3d::Zero();
  centroid = Eigen::Vector3d::Zero();
  for (std::uint32_t i = 0; i < n; ++i) {
    const Eigen::Vector3d a = corners[i].cast<double>();
    const Eigen::Vector3d b = corners[(i + 1) % n].cast<double>();
    normal.x() += (a.y() - b.y()) * (a.z() + b.z());
    normal.y() += (a.z() - b.z()) * (a.x() + b.x());
    normal.z() += (a.x() - b.x()) * (a.y() + b.y());
    centroid += a;
  }
  centroid /= n;
  const double normal_len = normal.norm();
  if (!(normal_len > 0.0) || !std::isfinite(normal_len)) return false;
  normal /= normal_len;
  return true;
}

// A convex quadrilateral (the common case) is the fan (0 1 2), (0 2 3): every corner turns left
// about the normal by more than the straight tolerance. (With five corners or more, all-left
// turns are not enough, a pentagram has them, so those always go through ear clipping.)
bool convex_quad(std::span<const Eigen::Vector3f> corners, const Eigen::Vector3d& normal) {
  for (std::uint32_t b = 0; b < 4; ++b) {
    const Eigen::Vector3d a = corners[(b + 3) % 4].cast<double>();
    const Eigen::Vector3d m = corners[b].cast<double>();
    const Eigen::Vector3d c = corners[(b + 1) % 4].cast<double>();
    const double turn = (m - a).cross(c - m).dot(normal);
    if (!(turn > 0.0 && turn * turn > kStraightSine * kStraightSine * (m - a).squaredNorm() * (c - m).squaredNorm()))
      return false;
  }
  return true;
}

// In-plane basis (u, v) with u × v = normal: the polygon is counter-clockwise in (u, v).
void project(std::span<const Eigen::Vector3f> corners, const Eigen::Vector3d& normal, const Eigen::Vector3d& centroid,
             EarClippingScratch& s) {
  const auto n = static_cast<std::uint32_t>(corners.size());
  const Eigen::Vector3d axis = std::abs(normal.x()) < 0.6 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  const Eigen::Vector3d u = axis.cross(normal).normalized();
  const Eigen::Vector3d v = normal.cross(u);
  s.x.resize(n);
  s.y.resize(n);
  s.prev.resize(n);
  s.next.resize(n);
  for (std::uint32_t i = 0; i < n; ++i) {
    const Eigen::Vector3d d = corners[i].cast<double>() - centroid;
    s.x[i] = d.dot(u);
    s.y[i] = d.dot(v);
    s.prev[i] = (i + n - 1) % n;
    s.next[i] = (i + 1) % n;
  }
}

// The walk for small faces: every corner tested against every other.
void clip_small(std::uint32_t n, std::vector<std::array<std::uint32_t, 3>>& out, EarClippingScratch& s) {
  const Plane pl{s};
  const auto is_ear = [&](std::uint32_t b) {
    const std::uint32_t a = s.prev[b], c = s.next[b];
    if (!pl.convex(a, b, c)) return false;  // reflex or straight
    for (std::uint32_t r = s.next[c]; r != a; r = s.next[r]) {
      ++s.steps;
      if (pl.same_point(r, a) || pl.same_point(r, b) || pl.same_point(r, c)) continue;
      if (pl.inside(r, a, b, c)) return false;
    }
    return true;
  };
  const auto clip = [&](std::uint32_t b) {
    const std::uint32_t a = s.prev[b], c = s.next[b];
    out.push_back({a, b, c});
    s.next[a] = c;
    s.prev[c] = a;
  };

  // Starting at corner 1 makes the first ear (0, 1, 2), then (0, 2, 3), ...: a convex polygon
  // comes out as the usual fan from corner 0, as other tools triangulate it.
  std::uint32_t remaining = n;
  std::uint32_t i = 1;
  std::uint32_t misses = 0;
  while (remaining > 3) {
    if (is_ear(i)) {
      const std::uint32_t after = s.next[i];
      clip(i);
      --remaining;
      misses = 0;
      i = after;
      continue;
    }
    i = s.next[i];
    if (++misses < remaining) continue;
    // A full turn without an ear (self-intersecting or numerically degenerate): cut the most
    // convex corner so the count stays n − 2 and the walk terminates.
    std::uint32_t best = i;
    double best_turn = -std::numeric_limits<double>::infinity();
    std::uint32_t j = i;
    do {
      const double turn = pl.cross(s.prev[j], j, s.next[j]);
      if (turn > best_turn) {
        best_turn = turn;
        best = j;
      }
      j = s.next[j];
    } while (j != i);
    i = s.next[best];
    clip(best);
    --remaining;
    misses = 0;
  }
  out.push_back({s.prev[i], i, s.next[i]});
}

// Large faces: the indexed clipper on the projected ring; false when its step budget ran out.
bool clip_large(std::uint32_t n, std::vector<std::array<std::uint32_t, 3>>& out, EarClippingScratch& s) {
  Polygon2 ring(n);
  for (std::uint32_t i = 0; i < n; ++i) ring[i] = Eigen::Vector2d(s.x[i], s.y[i]);
  TriangulationWork work;
  for (const auto& t : triangulate_polygon_with_holes(ring, {}, kStraightSine, &work))
    out.push_back({static_cast<std::uint32_t>(t[0]), static_cast<std::uint32_t>(t[1]), static_cast<std::uint32_t>(t[2])});
  s.steps += work.steps;
  return !work.exhausted;
}

// Sliver (a, m, b) and the triangle across its long edge (a, b, x) become (a, m, x), (m, b, x),
// which both have area.
void flip(std::array<std::uint32_t, 3>& sliver, int k, std::array<std::uint32_t, 3>& across, int j) {
  const std::uint32_t a = sliver[k], m = sliver[(k + 1) % 3], b = sliver[(k + 2) % 3], x = across[(j + 2) % 3];
  sliver = {a, m, x};
  across = {m, b, x};
}

// A corner on a straight stretch of the boundary is never an ear, so it can end up in a
// zero-area triangle (a, m, b) with m between a and b: flipped with the triangle across (a, b).
// Small faces: passes over every triangle, searching each sliver's neighbour.
void flip_slivers_small(const Plane& pl, std::vector<std::array<std::uint32_t, 3>>& out, std::size_t first_out,
                        std::uint32_t n) {
  const std::size_t end_out = out.size();
  const auto flip_sliver = [&](std::size_t t) {
    for (int k = 0; k < 3; ++k) {
      if (!pl.sliver_at(out[t], k)) continue;
      const std::uint32_t a = out[t][k], b = out[t][(k + 2) % 3];
      for (std::size_t w = first_out; w < end_out; ++w) {
        for (int j = 0; w != t && j < 3; ++j) {
          if (out[w][j] != a || out[w][(j + 1) % 3] != b) continue;
          flip(out[t], k, out[w], j);
          return true;
        }
      }
    }
    return false;
  };
  for (std::uint32_t pass = 0; pass < n; ++pass) {
    bool changed = false;
    for (std::size_t t = first_out; t < end_out; ++t) changed |= flip_sliver(t);
    if (!changed) break;
  }
}

// Large faces: the same flips from a work list, neighbours found through a map of directed edges,
// at most 4 flips a triangle (a flip makes two triangles with area unless a fourth corner is
// collinear too, so long runs need a few).
void flip_slivers_large(const Plane& pl, std::vector<std::array<std::uint32_t, 3>>& out, std::size_t first_out) {
  std::unordered_map<std::uint64_t, std::size_t> across;  // directed edge (a, b) → triangle holding it
  const auto key = [](std::uint32_t a, std::uint32_t b) { return (std::uint64_t{a} << 32) | b; };
  const auto link = [&](std::size_t t, bool add) {
    for (int k = 0; k < 3; ++k) {
      const std::uint64_t e = key(out[t][k], out[t][(k + 1) % 3]);
      if (add) across[e] = t;
      else if (auto it = across.find(e); it != across.end() && it->second == t) across.erase(it);
    }
  };
  // The triangle w across sliver t's long edge at corner k, and where that edge starts in w.
  const auto partner = [&](std::size_t t, int k, int& j) -> std::size_t {
    const std::uint32_t a = out[t][k], m = out[t][(k + 1) % 3], b = out[t][(k + 2) % 3];
    const auto it = across.find(key(a, b));
    if (it == across.end() || it->second == t) return t;
    const std::size_t w = it->second;
    for (j = 0; j < 3; ++j)
      if (out[w][j] == a && out[w][(j + 1) % 3] == b && out[w][(j + 2) % 3] != m) return w;
    return t;  // (a, b, m): the sliver folded onto itself, nothing to flip
  };
  std::vector<std::size_t> work;
  for (std::size_t t = first_out; t < out.size(); ++t)
    if (pl.sliver(out[t])) work.push_back(t);
  if (work.empty()) return;  // the usual case: no map needed
  across.reserve(3 * (out.size() - first_out));
  for (std::size_t t = first_out; t < out.size(); ++t) link(t, true);
  for (std::size_t flips = 0; !work.empty() && flips < 4 * (out.size() - first_out);) {
    const std::size_t t = work.back();
    work.pop_back();
    for (int k = 0, j = 0; k < 3; ++k) {
      if (!pl.sliver_at(out[t], k)) continue;
      const std::size_t w = partner(t, k, j);
      if (w == t) continue;
      link(t, false);
      link(w, false);
      flip(out[t], k, out[w], j);
      link(t, true);
      link(w, true);
      work.push_back(t);
      work.push_back(w);
      ++flips;
      break;
    }
  }
}

}  // namespace

bool triangulate_polygon(std::span<const Eigen::Vector3f> corners, std::vector<std::array<std::uint32_t, 3>>& out,
                         EarClippingScratch& s) {
  const auto n = static_cast<std::uint32_t>(corners.size());
  if (n < 3) return true;
  if (n == 3) {
    out.push_back({0, 1, 2});
    return true;
  }
  Eigen::Vector3d normal, centroid;
  if (!plane_of(corners, normal, centroid) || (n == 4 && convex_quad(corners, normal))) {
    fan(n, out);  // no area (or NaN corners): nothing better than a fan; a convex quad is one
    return true;
  }
  project(corners, normal, centroid, s);
  const Plane pl{s};
  const std::size_t first_out = out.size();
  if (n < kLargeFace) {
    clip_small(n, out, s);
    flip_slivers_small(pl, out, first_out, n);
    return true;
  }
  const bool within_budget = clip_large(n, out, s);
  flip_slivers_large(pl, out, first_out);
  return within_budget;
}

}  // namespace lamina::geometry_detail
