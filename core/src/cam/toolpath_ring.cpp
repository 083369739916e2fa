// Kerf compensation of a pass in 5 axes, corner marks, and pieces of a closed path by arc length.
#include "cam/toolpath_ring.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace lamina::cam_detail {
namespace {

// A mitre longer than this many half-kerfs is cut short: needle-sharp spikes of an outline would
// otherwise send the jet far out into the scrap (and into a neighbour).
constexpr double kMitreLimit = 8.0;

Eigen::Vector3d unit_or(const Eigen::Vector3d& v, const Eigen::Vector3d& fallback) {
  const double n = v.norm();
  return n > 1e-12 ? Eigen::Vector3d(v / n) : fallback;
}

// v without its component along the unit a, normalised.
Eigen::Vector3d perpendicular_to(const Eigen::Vector3d& v, const Eigen::Vector3d& a, const Eigen::Vector3d& fallback) {
  return unit_or(v - v.dot(a) * a, fallback);
}

}  // namespace

CompensatedPass compensate_pass(const LayerOutline& outline, const CutPass& pass, const SheetFrame& frame,
                                bool reverse, double half_kerf_mm) {
  const int n = static_cast<int>(pass.lines.size());
  CompensatedPass out;
  out.points.resize(static_cast<std::size_t>(n));
  out.station_of.resize(static_cast<std::size_t>(n));
  std::vector<Eigen::Vector3d> top(n), bottom(n), axis(n), scrap(n);
  for (int i = 0; i < n; ++i) {
    const int s = reverse ? n - 1 - i : i;
    const CutLine& l = pass.lines[static_cast<std::size_t>(s)];
    const CutStation& st = outline.stations[static_cast<std::size_t>(s)];
    out.station_of[static_cast<std::size_t>(i)] = s;
    top[i] = frame.point(l.top_mm);
    bottom[i] = frame.point(l.bottom_mm);
    axis[i] = frame.direction(l.tool_axis).normalized();
    scrap[i] = frame.direction(Eigen::Vector3d(st.normal.x(), st.normal.y(), 0.0));
  }
  // Normal of the ruled face between lines i and i+1, towards the scrap. The cross product of the
  // quad's diagonals is its normal even where the tops (or the bottoms) coincide, as in a fan of
  // lines at a corner.
  std::vector<Eigen::Vector3d> face(n);
  for (int i = 0; i < n; ++i) {
    const int j = (i + 1) % n;
    const Eigen::Vector3d side = scrap[i] + scrap[j];
    Eigen::Vector3d m = (bottom[j] - top[i]).cross(top[j] - bottom[i]);
    m = unit_or(m, unit_or(side, scrap[i]));
    if (m.dot(side) < 0.0) m = -m;
    face[i] = m;
  }
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d& a = axis[i];
    const Eigen::Vector3d fallback = perpendicular_to(scrap[i], a, scrap[i]);
    const Eigen::Vector3d m1 = perpendicular_to(face[(i + n - 1) % n], a, fallback);
    const Eigen::Vector3d m2 = perpendicular_to(face[i], a, fallback);
    // The point at distance h from both faces (in the plane across the line): h (m1 + m2) / (1 + m1·m2).
    const double c = 1.0 + m1.dot(m2);
    Eigen::Vector3d d = c > 2.0 / (kMitreLimit * kMitreLimit) ? Eigen::Vector3d(half_kerf_mm * (m1 + m2) / c)
                                                              : Eigen::Vector3d(half_kerf_mm * fallback);
    if (d.norm() > kMitreLimit * half_kerf_mm) d *= kMitreLimit * half_kerf_mm / d.norm();
    // The offset line, re-intersected with both faces.
    const Eigen::Vector3d p = top[i] + d;
    PathPoint& pt = out.points[static_cast<std::size_t>(i)];
    pt.axis = a;
    pt.tip = p + (-p.z() / a.z()) * a;
    pt.bottom = p + ((-frame.thickness_mm - p.z()) / a.z()) * a;
    const Eigen::Vector2d h2 = d.head<2>().norm() > 1e-9 ? Eigen::Vector2d(d.head<2>()) : Eigen::Vector2d(scrap[i].head<2>());
    pt.scrap = h2.norm() > 1e-12 ? Eigen::Vector2d(h2.normalized()) : Eigen::Vector2d(1.0, 0.0);
  }
  out.arc_mm.resize(static_cast<std::size_t>(n));
  double s = 0.0;
  for (int i = 0; i < n; ++i) {
    out.arc_mm[static_cast<std::size_t>(i)] = s;
    s += (out.points[static_cast<std::size_t>((i + 1) % n)].tip - out.points[static_cast<std::size_t>(i)].tip).norm();
  }
  out.length_mm = s;
  return out;
}

void mark_corners(std::vector<PathPoint>& points, double corner_angle_rad, double min_fraction) {
  const std::size_t n = points.size();
  if (n < 3) return;
  for (std::size_t i = 0; i < n; ++i) {
    // The nearest points before and after that are not on top of this one (fans share a tip).
    const Eigen::Vector2d here = points[i].tip.head<2>();
    Eigen::Vector2d in = Eigen::Vector2d::Zero(), out = Eigen::Vector2d::Zero();
    for (std::size_t k = 1; k < n && in.norm() < 1e-6; ++k) in = here - points[(i + n - k) % n].tip.head<2>();
    for (std::size_t k = 1; k < n && out.norm() < 1e-6; ++k) out = points[(i + k) % n].tip.head<2>() - here;
    double factor = 1.0;
    if (in.norm() >= 1e-6 && out.norm() >= 1e-6) {
      const double turn = std::acos(std::clamp(in.normalized().dot(out.normalized()), -1.0, 1.0));
      if (turn > corner_angle_rad) factor = std::max(min_fraction, std::cos(0.5 * turn));
    }
    points[i].corner_factor = factor;
  }
}

double arc_at(const CompensatedPass& pass, double u) {
  const std::size_t n = pass.points.size();
  const double w = std::fmod(std::fmod(u, static_cast<double>(n)) + n, static_cast<double>(n));
  const std::size_t i = std::min(static_cast<std::size_t>(w), n - 1);
  const double next = i + 1 < n ? pass.arc_mm[i + 1] : pass.length_mm;
  return pass.arc_mm[i] + (w - static_cast<double>(i)) * (next - pass.arc_mm[i]);
}

namespace {

PathPoint lerp(const PathPoint& a, const PathPoint& b, double t) {
  PathPoint p;
  p.tip = a.tip + t * (b.tip - a.tip);
  p.bottom = a.bottom + t * (b.bottom - a.bottom);
  p.axis = (p.tip - p.bottom).normalized();
  p.scrap = (a.scrap + t * (b.scrap - a.scrap));
  p.scrap = p.scrap.norm() > 1e-12 ? Eigen::Vector2d(p.scrap.normalized()) : a.scrap;
  p.feed_mm_per_s = std::min(a.feed_mm_per_s, b.feed_mm_per_s);
  p.corner_factor = 1.0;
  // A point between two is slowed by a corner whose zone reaches it (the trail-back's corner
  // speeds). The angle heuristic's infinite zones slow whole moves from their ends only, as before.
  const double len = (b.tip - a.tip).norm();
  for (const auto& [end, d] : {std::pair{&a, t * len}, std::pair{&b, (1.0 - t) * len}})
    if (std::isfinite(end->slow_zone_mm) && d <= end->slow_zone_mm && end->corner_factor < p.corner_factor)
      p.corner_factor = end->corner_factor, p.slow_zone_mm = end->slow_zone_mm - d;
  return p;
}

}  // namespace

std::vector<FeedPiece> feed_pieces(const PathPoint& a, const PathPoint& b) {
  const double len = (b.tip - a.tip).norm();
  const auto factor_at = [&](double x) {
    double f = 1.0;
    if (x <= a.slow_zone_mm) f = std::min(f, a.corner_factor);
    if (len - x <= b.slow_zone_mm) f = std::min(f, b.corner_factor);
    return f;
  };
  // Where a's zone ends and b's begins, inside the move.
  std::vector<double> cuts{0.0};
  for (const double x : {a.slow_zone_mm, len - b.slow_zone_mm})
    if (x > 1e-9 && x < len - 1e-9) cuts.push_back(x);
  std::sort(cuts.begin(), cuts.end());
  cuts.push_back(len);
  std::vector<FeedPiece> out;
  for (std::size_t k = 0; k + 1 < cuts.size(); ++k) {
    const double f = factor_at(0.5 * (cuts[k] + cuts[k + 1]));
    if (!out.empty() && out.back().factor == f) out.pop_back();  // one piece, extended below
    out.push_back({k + 2 == cuts.size() ? b : lerp(a, b, cuts[k + 1] / len), f});
  }
  if (len <= 0.0) out = {{b, std::min(a.corner_factor, b.corner_factor)}};
  return out;
}

namespace {

// The point at arc length s on the closed path (any real s: it wraps).
PathPoint point_at(const CompensatedPass& pass, double s) {
  const std::size_t n = pass.points.size();
  const double L = pass.length_mm;
  const double w = L > 0.0 ? std::fmod(std::fmod(s, L) + L, L) : 0.0;
  std::size_t i = static_cast<std::size_t>(std::upper_bound(pass.arc_mm.begin(), pass.arc_mm.end(), w) - pass.arc_mm.begin());
  i = i == 0 ? 0 : i - 1;
  const double next = i + 1 < n ? pass.arc_mm[i + 1] : L;
  const double seg = next - pass.arc_mm[i];
  const double t = seg > 1e-12 ? (w - pass.arc_mm[i]) / seg : 0.0;
  return lerp(pass.points[i], pass.points[(i + 1) % n], t);
}

}  // namespace

std::vector<PathPoint> sub_path(const CompensatedPass& pass, double s0_mm, double s1_mm) {
  const std::size_t n = pass.points.size();
  const double L = pass.length_mm;
  std::vector<PathPoint> out;
  out.push_back(point_at(pass, s0_mm));
  // Every vertex strictly inside (s0, s1), walking forward from s0 (with wrap-around).
  const double base = std::floor(s0_mm / L) * L;
  for (int lap = 0; lap < 3; ++lap)
    for (std::size_t i = 0; i < n; ++i) {
      const double s = base + lap * L + pass.arc_mm[i];
      if (s > s0_mm + 1e-9 && s < s1_mm - 1e-9) out.push_back(pass.points[i]);
    }
  out.push_back(point_at(pass, s1_mm));
  return out;
}

double ray_to_ring(const std::vector<PathPoint>& ring, const Eigen::Vector2d& from, const Eigen::Vector2d& dir) {
  double best = std::numeric_limits<double>::infinity();
  const std::size_t n = ring.size();
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector2d a = ring[i].tip.head<2>(), b = ring[(i + 1) % n].tip.head<2>();
    const Eigen::Vector2d e = b - a;
    const double den = dir.x() * e.y() - dir.y() * e.x();
    if (std::abs(den) < 1e-15) continue;
    const Eigen::Vector2d w = a - from;
    const double t = (w.x() * e.y() - w.y() * e.x()) / den;  // along the ray
    const double u = (w.x() * dir.y() - w.y() * dir.x()) / den;  // along the edge
    if (t > 1e-3 && u >= 0.0 && u <= 1.0) best = std::min(best, t);
  }
  return best;
}

}  // namespace lamina::cam_detail
