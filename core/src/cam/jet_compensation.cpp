#include "jet_compensation.hpp"

#include <fmt/format.h>

#include <cmath>

namespace lamina::cam_detail {
namespace {

constexpr double kMinTaperLeanMm = 0.01;  // across a vertical line: below this it stays vertical

// Horizontal unit direction of travel at point i (from its neighbours), or zero where the tip
// does not move (a fan of lines at a corner turns the head about one tip).
Eigen::Vector3d travel_at(const std::vector<PathPoint>& pts, std::size_t i, bool closed) {
  const std::size_t n = pts.size();
  const std::size_t prev = i > 0 ? i - 1 : (closed ? n - 1 : i), next = i + 1 < n ? i + 1 : (closed ? 0 : i);
  Eigen::Vector3d d = pts[next].tip - pts[prev].tip;
  d.z() = 0.0;
  return d.norm() > 1e-9 ? Eigen::Vector3d(d.normalized()) : Eigen::Vector3d::Zero();
}

// The line from tip to bottom, its lean held to the tilt limit (the tip kept: it is the top wall).
bool hold_to_limit(PathPoint& q, double tilt_max_rad, double thickness_mm) {
  Eigen::Vector3d line = q.tip - q.bottom;
  const double across = line.head<2>().norm(), limit = thickness_mm * std::tan(tilt_max_rad);
  const bool held = across > limit + 1e-12;
  if (held) {
    line.head<2>() *= limit / across;
    q.bottom = q.tip - line;
  }
  q.axis = line.normalized();
  return held;
}

}  // namespace

std::expected<std::size_t, Error> compensate_jet(std::vector<PathPoint>& points, std::span<const double> separation_mm_per_s,
                                                 const JetCompensationInput& in) {
  if (in.mode == JetCompensationMode::off) return 0;
  if (!in.kerf || separation_mm_per_s.size() != points.size())
    return std::unexpected(Error{ErrorCode::invalid_argument, "jet compensation: no kerf model or no separation speed per line"});
  const std::vector<PathPoint> planned = points;  // travel directions from the uncompensated path
  std::size_t held = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    PathPoint& q = points[i];
    const double path_mm = in.thickness_mm / std::max(q.axis.z(), 1e-6);
    const double ratio = q.feed_mm_per_s * q.corner_factor / separation_mm_per_s[i];
    auto kerf = kerf_at(*in.kerf, path_mm, ratio);
    if (!kerf) return std::unexpected(Error{kerf.error().code, fmt::format("line {}: {}", i, kerf.error().message)});
    const Eigen::Vector3d scrap(q.scrap.x(), q.scrap.y(), 0.0);
    // The exit trails the entry by the trail-back: aim it that far ahead where that lag would
    // leave more than the corner allowance. Elsewhere (straight cuts, gentle curves) a lag along
    // the cut leaves the wall where it is, and leaning would only turn C with the path.
    const bool lean = in.mode == JetCompensationMode::full && q.lag_beyond_allowance;
    double top = kerf->top_width_mm / 2.0, bottom = kerf->bottom_width_mm / 2.0;
    // A vertical line whose walls the taper moves by less than kMinTaperLeanMm stays vertical,
    // at the mean of the two: a head tilted that little turns C at every change of direction,
    // and the rotary rates then slow the cut for nothing (docs/jet.md).
    if (!lean && q.axis.z() >= 1.0 - 1e-15 && std::abs(top - bottom) < kMinTaperLeanMm) top = bottom = 0.5 * (top + bottom);
    q.tip += (top - in.half_kerf_mm) * scrap;
    q.bottom += (bottom - in.half_kerf_mm) * scrap;
    if (lean) q.bottom += kerf->trail_back_mm * travel_at(planned, i, in.closed);
    q.trail_back_mm = kerf->trail_back_mm;
    q.tilt_limited = hold_to_limit(q, in.tilt_max_rad, in.thickness_mm);
    held += q.tilt_limited;
  }
  return held;
}

}  // namespace lamina::cam_detail
