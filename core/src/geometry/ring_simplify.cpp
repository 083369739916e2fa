// Rings with fewer corners on a chosen side (ring_simplify.hpp).
#include "geometry/ring_simplify.hpp"

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

namespace lamina::geometry_detail {
using ClipperLib::IntPoint;
using ClipperLib::Path;
using ClipperLib::Paths;

namespace {

// Douglas–Peucker on the open chain of ring corners a..b (indices taken modulo the size), its
// ends kept: marks the corners to keep.
void simplify_chain(const Path& ring, std::size_t a, std::size_t b, double tol_units, std::vector<bool>& keep) {
  const std::size_t n = ring.size();
  std::vector<std::pair<std::size_t, std::size_t>> spans{{a, b}};
  while (!spans.empty()) {
    const auto [s, e] = spans.back();
    spans.pop_back();
    const IntPoint& ps = ring[s % n];
    const double ex = static_cast<double>(ring[e % n].X - ps.X), ey = static_cast<double>(ring[e % n].Y - ps.Y);
    const double len = std::hypot(ex, ey);
    double worst = 0.0;
    std::size_t at = s;
    for (std::size_t i = s + 1; i < e; ++i) {
      const double px = static_cast<double>(ring[i % n].X - ps.X), py = static_cast<double>(ring[i % n].Y - ps.Y);
      // Distance to the segment (not the line), so a chord never strays past its span.
      const double u = len > 0.0 ? std::clamp((px * ex + py * ey) / (len * len), 0.0, 1.0) : 0.0;
      const double d = std::hypot(px - u * ex, py - u * ey);
      if (d > worst) {
        worst = d;
        at = i;
      }
    }
    if (worst <= tol_units) continue;
    keep[at % n] = true;
    spans.emplace_back(s, at);
    spans.emplace_back(at, e);
  }
}

// How far the ring turns at corner i (radians, either way).
double turn_at(const Path& ring, std::size_t i) {
  const std::size_t n = ring.size();
  const IntPoint& p = ring[(i + n - 1) % n];
  const IntPoint& q = ring[i];
  const IntPoint& r = ring[(i + 1) % n];
  const double ax = static_cast<double>(q.X - p.X), ay = static_cast<double>(q.Y - p.Y);
  const double bx = static_cast<double>(r.X - q.X), by = static_cast<double>(r.Y - q.Y);
  return std::abs(std::atan2(ax * by - ay * bx, ax * bx + ay * by));
}

// The corners Douglas–Peucker keeps on a closed ring: every dropped corner lies within
// `tol_units` of the chord that replaces it. Corners where the ring turns by more than
// keep_turn_rad are kept (with fewer than two such, corner 0 or the sharp one and the corner
// farthest from it).
std::vector<bool> corners_kept(const Path& ring, double tol_units, double keep_turn_rad) {
  const std::size_t n = ring.size();
  std::vector<bool> keep(n, false);
  std::vector<std::size_t> kept;
  for (std::size_t i = 0; i < n; ++i)
    if (turn_at(ring, i) > keep_turn_rad) {
      keep[i] = true;
      kept.push_back(i);
    }
  if (kept.size() < 2) {  // corner 0 (or the one sharp corner) and the corner farthest from it
    const std::size_t first = kept.empty() ? 0 : kept.front();
    auto dist2 = [&](std::size_t i) {
      const double dx = static_cast<double>(ring[i].X - ring[first].X);
      const double dy = static_cast<double>(ring[i].Y - ring[first].Y);
      return dx * dx + dy * dy;
    };
    std::size_t far = first;
    for (std::size_t i = 0; i < n; ++i)
      if (dist2(i) > dist2(far)) far = i;
    keep[first] = keep[far] = true;
    kept = {std::min(first, far), std::max(first, far)};
  }
  for (std::size_t k = 0; k < kept.size(); ++k) {
    const std::size_t a = kept[k];
    const std::size_t b = k + 1 < kept.size() ? kept[k + 1] : kept.front() + n;  // around the end
    simplify_chain(ring, a, b, tol_units, keep);
  }
  return keep;
}

// The kept corners as a ring, and which of its edges replaced dropped corners.
SimplifiedRing kept_ring(const Path& ring, const std::vector<bool>& keep) {
  SimplifiedRing out;
  for (std::size_t i = 0; i < ring.size(); ++i)
    if (keep[i]) out.ring.push_back(ring[i]);
  for (std::size_t i = 0; i < ring.size(); ++i)
    if (keep[i]) out.chord.push_back(keep[(i + 1) % ring.size()] ? 0 : 1);
  return out;
}

// A simple ring (Clipper finds no crossing to split) with the same area as `ring`, to the
// doubles' rounding of the areas in nm² (a ring of R 80 mm is 2·10¹⁶ nm², whose step is 4).
bool is_simple(const Path& ring) {
  Paths parts;
  ClipperLib::SimplifyPolygon(ring, parts, ClipperLib::pftNonZero);
  if (parts.size() != 1) return false;
  const double area = ClipperLib::Area(ring);
  return std::abs(ClipperLib::Area(parts.front()) - area) <= std::max(1.0, 1e-12 * std::abs(area));
}

}  // namespace

SimplifiedRing simplified_beside_marked(const Path& ring, double by_mm, double keep_turn_rad) {
  const SimplifiedRing unchanged{ring, std::vector<char>(ring.size(), 0)};
  const Paths moved = offset_mitre({ring}, by_mm);
  if (moved.size() != 1 || !ClipperLib::Orientation(moved.front())) return unchanged;
  const Path& around = moved.front();
  SimplifiedRing out = kept_ring(around, corners_kept(around, 0.5 * std::abs(by_mm) * kClipperUnitsPerMm, keep_turn_rad));
  const Path& r = out.ring;
  if (r.size() >= ring.size() || r.size() < 3 || !ClipperLib::Orientation(r) || !is_simple(r)) return unchanged;
  // Belt and braces: the side must hold (else keep the ring itself).
  const Paths wrong_side = by_mm > 0.0 ? boolean(ClipperLib::ctDifference, {ring}, {r})
                                       : boolean(ClipperLib::ctDifference, {r}, {ring});
  if (area_mm2(wrong_side) != 0.0) return unchanged;
  return out;
}

Path simplified_beside(const Path& ring, double by_mm, double keep_turn_rad) {
  return simplified_beside_marked(ring, by_mm, keep_turn_rad).ring;
}

}  // namespace lamina::geometry_detail
