#include "jet_corners.hpp"

#include <fmt/format.h>

#include <cmath>
#include <numbers>

namespace lamina::cam_detail {
namespace {

double cross2(const Eigen::Vector2d& a, const Eigen::Vector2d& b) { return a.x() * b.y() - a.y() * b.x(); }

// The closed tip path as the corner rule reads it: arc length at each point, and the signed turn
// (rad, + to the left) of the path at each point, between the directions from the previous
// distinct tip and to the next. A fan of lines sharing one tip turns once, at its first point.
struct TurnRing {
  std::vector<double> arc_mm, turn_rad;
  double length_mm = 0.0;
};

TurnRing turn_ring(const std::vector<PathPoint>& pts) {
  const std::size_t n = pts.size();
  TurnRing r;
  r.arc_mm.resize(n);
  r.turn_rad.assign(n, 0.0);
  for (std::size_t i = 0; i < n; ++i) {
    r.arc_mm[i] = r.length_mm;
    r.length_mm += (pts[(i + 1) % n].tip.head<2>() - pts[i].tip.head<2>()).norm();
  }
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector2d here = pts[i].tip.head<2>();
    if ((here - pts[(i + n - 1) % n].tip.head<2>()).norm() < 1e-6) continue;  // not the fan's first
    Eigen::Vector2d in = Eigen::Vector2d::Zero(), out = Eigen::Vector2d::Zero();
    for (std::size_t k = 1; k < n && in.norm() < 1e-6; ++k) in = here - pts[(i + n - k) % n].tip.head<2>();
    for (std::size_t k = 1; k < n && out.norm() < 1e-6; ++k) out = pts[(i + k) % n].tip.head<2>() - here;
    if (in.norm() >= 1e-6 && out.norm() >= 1e-6) r.turn_rad[i] = std::atan2(cross2(in, out), in.dot(out));
  }
  return r;
}

// Calls f(j, distance) for every point j within `reach` of point i along the closed path, both
// ways (i itself at 0, each point once).
template <class F>
void for_each_within(const TurnRing& r, std::size_t i, double reach, F&& f) {
  const std::size_t n = r.arc_mm.size();
  const auto gap = [&](std::size_t a, std::size_t b) {  // arc length from a forward to b
    const double d = r.arc_mm[b] - r.arc_mm[a];
    return d >= 0.0 ? d : d + r.length_mm;
  };
  f(i, 0.0);
  std::size_t ahead = 1, behind = 1;
  for (; ahead < n && gap(i, (i + ahead) % n) <= reach; ++ahead) f((i + ahead) % n, gap(i, (i + ahead) % n));
  for (; behind < n - ahead + 1 && gap((i + n - behind) % n, i) <= reach; ++behind)
    f((i + n - behind) % n, gap((i + n - behind) % n, i));
}

struct Window {
  double turn_rad = 0.0;    // how much the path turns within it, either way (at most π)
  bool toward_scrap = false;  // its net turn is towards the scrap side: an inside corner of the part
};

// The scrap lies left of the travel when the part is on the jet's right (ToolpathParams::part_on_right).
Window window_at(const TurnRing& r, std::size_t i, double lag_mm, bool scrap_left) {
  double total = 0.0, net = 0.0;
  for_each_within(r, i, lag_mm, [&](std::size_t j, double) {
    total += std::abs(r.turn_rad[j]);
    net += r.turn_rad[j];
  });
  return {std::min(total, std::numbers::pi), net != 0.0 && (net > 0.0) == scrap_left};
}

double corner_error_mm(double lag_mm, double turn_rad) { return lag_mm * std::sin(0.5 * turn_rad); }

}  // namespace

std::expected<std::size_t, Error> jet_corner_speeds(std::vector<PathPoint>& pts, std::span<const double> separation_mm_per_s,
                                                    const JetCornerInput& in) {
  const std::size_t n = pts.size();
  if (!in.kerf || separation_mm_per_s.size() != n)
    return std::unexpected(Error{ErrorCode::invalid_argument, "jet corners: no kerf model or no separation speed per line"});
  const TurnRing ring = turn_ring(pts);
  std::vector<double> factor(n, 1.0), zone(n, 0.0);
  std::size_t floored = 0;
  for (std::size_t i = 0; i < n && n >= 3; ++i) {
    const double path_mm = in.thickness_mm / std::max(pts[i].axis.z(), 1e-6);
    const double full_ratio = pts[i].feed_mm_per_s / separation_mm_per_s[i];
    const auto lag_at = [&](double ratio) -> std::expected<double, Error> {
      auto k = kerf_at(*in.kerf, path_mm, ratio);
      if (!k) return std::unexpected(Error{k.error().code, fmt::format("corner at line {}: {}", i, k.error().message)});
      return k->trail_back_mm;
    };
    const auto full_lag = lag_at(full_ratio);
    if (!full_lag) return std::unexpected(full_lag.error());
    const Window w = window_at(ring, i, *full_lag, in.part_on_right);
    if (corner_error_mm(*full_lag, w.turn_rad) <= in.corners.error_mm) continue;
    pts[i].lag_beyond_allowance = true;
    if (w.toward_scrap && in.corners.inside == InsideCorners::keep) continue;
    // The fastest fraction whose lag keeps the corner within the allowance (the error grows with
    // the lag, and the lag with the feed): bisection between the floor and the full feed.
    double lo = in.corners.min_fraction, hi = 1.0;
    const auto fits = [&](double fraction) -> std::expected<bool, Error> {
      auto lag = lag_at(fraction * full_ratio);
      if (!lag) return std::unexpected(lag.error());
      return corner_error_mm(*lag, window_at(ring, i, *lag, in.part_on_right).turn_rad) <= in.corners.error_mm;
    };
    auto floor_fits = fits(lo);
    if (!floor_fits) return std::unexpected(floor_fits.error());
    if (!*floor_fits) {
      ++floored;
      hi = lo;
    }
    for (int k = 0; k < 40 && hi - lo > 1e-4; ++k) {
      const double mid = 0.5 * (lo + hi);
      auto ok = fits(mid);
      if (!ok) return std::unexpected(ok.error());
      (*ok ? lo : hi) = mid;
    }
    factor[i] = lo;
    zone[i] = *full_lag;
  }
  // Each slowed point holds its speed for its zone either way: a point within it takes the
  // slowest factor that reaches it, and how much further that factor's zone goes.
  for (std::size_t i = 0; i < n; ++i) pts[i].corner_factor = 1.0, pts[i].slow_zone_mm = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    if (factor[i] >= 1.0) continue;
    for_each_within(ring, i, zone[i], [&](std::size_t j, double d) {
      PathPoint& q = pts[j];
      const double rest = zone[i] - d;
      if (factor[i] < q.corner_factor || (factor[i] == q.corner_factor && rest > q.slow_zone_mm))
        q.corner_factor = factor[i], q.slow_zone_mm = rest;
    });
  }
  return floored;
}

}  // namespace lamina::cam_detail
