// Ear clipping of a 3D polygon in its Newell-normal plane, then a flip pass that removes the
// zero-area slivers left by corners lying on a straight edge.
#include "ear_clipping.hpp"

#include <Eigen/Geometry>

#include <cmath>
#include <limits>

namespace lamina::detail {
namespace {

void fan(std::uint32_t n, std::vector<std::array<std::uint32_t, 3>>& out) {
  for (std::uint32_t i = 1; i + 1 < n; ++i) out.push_back({0, i, i + 1});
}

// Corners turning by less than this angle (its sine) count as straight: float input rounds the
// collinear corners of a tilted polygon to turns of ~1e-7 either way.
constexpr double kStraightSine = 1e-5;

}  // namespace

void triangulate_polygon(std::span<const Eigen::Vector3f> corners, std::vector<std::array<std::uint32_t, 3>>& out,
                         EarClippingScratch& s) {
  const auto n = static_cast<std::uint32_t>(corners.size());
  if (n < 3) return;
  if (n == 3) {
    out.push_back({0, 1, 2});
    return;
  }

  // Newell normal and centroid, in double.
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
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
  if (!(normal_len > 0.0) || !std::isfinite(normal_len)) {  // no area (or NaN corners): nothing better than a fan
    fan(n, out);
    return;
  }
  normal /= normal_len;

  // A convex quadrilateral (the common case) is the fan (0 1 2), (0 2 3): every corner turns left
  // about the normal by more than the straight tolerance. (With five corners or more, all-left
  // turns are not enough, a pentagram has them, so those always go through ear clipping.)
  if (n == 4) {
    bool convex_quad = true;
    for (std::uint32_t b = 0; b < 4 && convex_quad; ++b) {
      const Eigen::Vector3d a = corners[(b + 3) % 4].cast<double>();
      const Eigen::Vector3d m = corners[b].cast<double>();
      const Eigen::Vector3d c = corners[(b + 1) % 4].cast<double>();
      const double turn = (m - a).cross(c - m).dot(normal);
      convex_quad = turn > 0.0 &&
                    turn * turn > kStraightSine * kStraightSine * (m - a).squaredNorm() * (c - m).squaredNorm();
    }
    if (convex_quad) {
      fan(n, out);
      return;
    }
  }

  // In-plane basis (u, v) with u × v = normal: the polygon is counter-clockwise in (u, v).
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

  const auto cross = [&s](std::uint32_t a, std::uint32_t b, std::uint32_t c) {
    return (s.x[b] - s.x[a]) * (s.y[c] - s.y[b]) - (s.y[b] - s.y[a]) * (s.x[c] - s.x[b]);
  };
  const auto length2 = [&s](std::uint32_t a, std::uint32_t b) {
    const double dx = s.x[b] - s.x[a], dy = s.y[b] - s.y[a];
    return dx * dx + dy * dy;
  };
  // |turn at b| ≤ kStraightSine · |ab| · |bc|, compared squared.
  const auto straight = [&](std::uint32_t a, std::uint32_t b, std::uint32_t c) {
    const double turn = cross(a, b, c);
    return turn * turn <= kStraightSine * kStraightSine * length2(a, b) * length2(b, c);
  };
  const auto convex = [&](std::uint32_t a, std::uint32_t b, std::uint32_t c) {
    return cross(a, b, c) > 0.0 && !straight(a, b, c);
  };
  const auto same_point = [&s](std::uint32_t a, std::uint32_t b) { return s.x[a] == s.x[b] && s.y[a] == s.y[b]; };
  // Point r inside or on triangle (a, b, c), which is counter-clockwise.
  const auto inside = [&](std::uint32_t r, std::uint32_t a, std::uint32_t b, std::uint32_t c) {
    const auto side = [&s, r](std::uint32_t p, std::uint32_t q) {
      return (s.x[q] - s.x[p]) * (s.y[r] - s.y[p]) - (s.y[q] - s.y[p]) * (s.x[r] - s.x[p]);
    };
    return side(a, b) >= 0.0 && side(b, c) >= 0.0 && side(c, a) >= 0.0;
  };
  const auto is_ear = [&](std::uint32_t b) {
    const std::uint32_t a = s.prev[b], c = s.next[b];
    if (!convex(a, b, c)) return false;  // reflex or straight
    for (std::uint32_t r = s.next[c]; r != a; r = s.next[r]) {
      if (same_point(r, a) || same_point(r, b) || same_point(r, c)) continue;
      if (inside(r, a, b, c)) return false;
    }
    return true;
  };
  const std::size_t first_out = out.size();
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
      const double turn = cross(s.prev[j], j, s.next[j]);
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

  // A corner on a straight stretch of the boundary is never an ear, so it can end up in a
  // zero-area triangle (a, m, b) with m between a and b. Flip it with the triangle across the
  // long edge (a, b, x) into (a, m, x) and (m, b, x), which both have area.
  const std::size_t end_out = out.size();
  const auto flip_sliver = [&](std::size_t t) {
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t a = out[t][k], m = out[t][(k + 1) % 3], b = out[t][(k + 2) % 3];
      if (!straight(a, m, b)) continue;
      // m strictly between a and b.
      if (!((s.x[m] - s.x[a]) * (s.x[b] - s.x[m]) + (s.y[m] - s.y[a]) * (s.y[b] - s.y[m]) > 0.0)) continue;
      for (std::size_t w = first_out; w < end_out; ++w) {
        for (int j = 0; w != t && j < 3; ++j) {
          if (out[w][j] != a || out[w][(j + 1) % 3] != b) continue;
          const std::uint32_t x = out[w][(j + 2) % 3];
          out[t] = {a, m, x};
          out[w] = {m, b, x};
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

}  // namespace lamina::detail
