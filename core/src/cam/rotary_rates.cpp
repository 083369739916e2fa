#include "rotary_rates.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace lamina::cam_detail {
namespace {

constexpr double kVerticalRad = 1e-9;  // below this tilt the axis is vertical and C is free

double tilt_of(const Eigen::Vector3d& axis) { return std::acos(std::clamp(axis.z(), -1.0, 1.0)); }

// The least time the head needs to turn from one axis to the next. A head reaches an axis two
// ways, A = +tilt at C = azimuth or A = -tilt at C = azimuth + 180° (the post picks, post_axes.cpp):
// the same side turns C by the azimuth's change, the other swings A through zero and C by the
// rest of a half turn (a taper that reverses at a slowed corner flips the azimuth by 180° with
// no C motion at all). A vertical axis holds C.
double turn_time_s(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double a_rate, double c_rate) {
  const double ta = tilt_of(a), tb = tilt_of(b);
  if (ta < kVerticalRad || tb < kVerticalRad) return std::abs(tb - ta) / a_rate;
  const double d = std::abs(std::remainder(std::atan2(b.y(), b.x()) - std::atan2(a.y(), a.x()), 2.0 * std::numbers::pi));
  const double same_side = std::max(std::abs(tb - ta) / a_rate, d / c_rate);
  const double flipped = std::max((ta + tb) / a_rate, (std::numbers::pi - d) / c_rate);
  return std::min(same_side, flipped);
}

}  // namespace

std::size_t limit_feeds_to_rotary_rates(std::vector<PathPoint>& pts, double a_max_rad_per_s, double c_max_rad_per_s) {
  const std::size_t n = pts.size();
  if (n < 2 || (!std::isfinite(a_max_rad_per_s) && !std::isfinite(c_max_rad_per_s))) return 0;
  std::vector<double> limit(n, std::numeric_limits<double>::infinity());
  for (std::size_t i = 0; i < n; ++i) {
    const PathPoint &a = pts[i], &b = pts[(i + 1) % n];
    const double travel_mm = std::max((b.tip - a.tip).norm(), (b.bottom - a.bottom).norm());
    const double turn_s = turn_time_s(a.axis, b.axis, a_max_rad_per_s, c_max_rad_per_s);
    if (!(turn_s > 0.0) || !(travel_mm > 0.0)) continue;
    // The move's feed is min(feeds) · min(corner factors); the fastest it may be is travel / turn.
    const double fastest = travel_mm / turn_s / std::min(a.corner_factor, b.corner_factor);
    limit[i] = std::min(limit[i], fastest);
    limit[(i + 1) % n] = std::min(limit[(i + 1) % n], fastest);
  }
  std::size_t lowered = 0;
  for (std::size_t i = 0; i < n; ++i)
    if (limit[i] < pts[i].feed_mm_per_s) pts[i].feed_mm_per_s = limit[i], ++lowered;
  return lowered;
}

}  // namespace lamina::cam_detail
