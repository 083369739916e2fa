// The rotary words of a pivot program: A and C as the controller will read them, written as
// rarely and as short as the far face allows, with X Y Z following the angles written.
#include "post/post_internal.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>
#include <utility>

namespace lamina::post_detail {

namespace {

// Only a small difference is held: never C a turn away, nor A through zero (the same axis).
constexpr double kMostHeldRad = 1.0 / deg_per_rad;
// The share of the far face's window an A run may use: C, chosen after it for each pose, keeps
// the rest (A and C tilt the axis in orthogonal directions: 0.9² + 0.43² = 1).
constexpr double kShareOfA = 0.9;

// An angle as the controller reads it when written with `decimals` decimals of a degree.
double rounded(double rad, int decimals) {
  const double scale = std::pow(10.0, decimals);
  return std::round(rad * deg_per_rad * scale) / scale / deg_per_rad;
}

int sign_class(double a) { return a > 0.0 ? 1 : a < 0.0 ? -1 : 0; }

// The value in [lo, hi] (rad) written with the fewest decimals of a degree (at most `decimals`),
// the one nearest the middle among equals; none when even `decimals` has no value there.
std::optional<double> fewest_decimals_in(double lo, double hi, int decimals) {
  const double mid_deg = 0.5 * (lo + hi) * deg_per_rad;
  for (int d = 0; d <= decimals; ++d) {
    const double scale = std::pow(10.0, d);
    const double k_lo = std::ceil(lo * deg_per_rad * scale), k_hi = std::floor(hi * deg_per_rad * scale);
    if (k_lo > k_hi) continue;
    const double k = std::clamp(std::round(mid_deg * scale), k_lo, k_hi);
    const double value = k / scale / deg_per_rad;
    if (value >= lo && value <= hi) return value;  // (the division can round across an end)
  }
  return std::nullopt;
}

// The A of every pose: consecutive poses share one A while one value keeps all their axes within
// `window_rad` of the planned A (with their own C), and A keeps its sign. A bevel's stations
// alternate in tilt by up to a few hundredths of a degree (a faceted model's chords, read on a
// thin layer's sub-slices); holding the last A written only worked where the two alternating
// values were each within the other's window, a value chosen for the run works wherever their
// windows overlap.
std::vector<double> a_runs(const std::vector<AxisPose>& poses, double window_rad, int decimals) {
  std::vector<double> out(poses.size());
  std::size_t i = 0;
  while (i < poses.size()) {
    const double a = poses[i].a_rad;
    double lo = a - window_rad, hi = a + window_rad;
    double value = fewest_decimals_in(lo, hi, decimals).value_or(rounded(a, decimals));
    std::size_t j = i + 1;
    for (; j < poses.size() && sign_class(poses[j].a_rad) == sign_class(a); ++j) {
      const double next_lo = std::max(lo, poses[j].a_rad - window_rad), next_hi = std::min(hi, poses[j].a_rad + window_rad);
      const auto v = next_lo <= next_hi ? fewest_decimals_in(next_lo, next_hi, decimals) : std::nullopt;
      if (!v) break;
      lo = next_lo;
      hi = next_hi;
      value = *v;
    }
    std::fill(out.begin() + static_cast<std::ptrdiff_t>(i), out.begin() + static_cast<std::ptrdiff_t>(j), value);
    i = j;
  }
  return out;
}

}  // namespace

std::vector<AxisPose> rounded_poses(const SheetToolpath& toolpath, const HeadKinematics& head, const PostParams& params,
                                    std::vector<AxisPose> poses) {
  if (head.rtcp) return poses;
  const int decimals = params.angular_decimals;
  // A and C are held while the axis they give stays so near the planned one that the cut's far
  // face moves by less than one linear step (the sheet's thickness times the angle between
  // them): rewriting A, C and the X Y Z they move for every station was a fifth of a pivot
  // program's bytes. The tip still lands where planned: X Y Z are computed from the angles held.
  const double far_face_mm = std::pow(10.0, -params.linear_decimals);
  const bool hold = params.hold_rotary_within_step && toolpath.thickness_mm > 0.0;
  auto near_enough = [&](double a, double c, const Eigen::Vector3d& planned) {
    const Eigen::Vector3d axis = tool_axis_at(a, c, head);
    return toolpath.thickness_mm * axis.cross(planned).norm() <= far_face_mm * axis.dot(planned);
  };
  // Fewer decimals where the far face allows them: C moves the axis by sin A times its own
  // error, so a nearly vertical head's C needs none.
  auto fewest = [&](double rad, auto&& fits) {
    for (int d = 0; d < decimals; ++d)
      if (const double r = rounded(rad, d); fits(r)) return r;
    return rounded(rad, decimals);
  };
  const std::vector<double> run_a =
      hold ? a_runs(poses, kShareOfA * std::atan(far_face_mm / toolpath.thickness_mm), decimals) : std::vector<double>{};
  std::optional<double> held_c;
  for (std::size_t i = 0; i < poses.size(); ++i) {
    AxisPose& p = poses[i];
    double a = rounded(p.a_rad, decimals), c = rounded(p.c_rad, decimals);
    if (hold) {
      const Eigen::Vector3d planned = tool_axis_at(p.a_rad, p.c_rad, head);
      if (near_enough(run_a[i], c, planned)) a = run_a[i];  // else this pose's own A, to the last decimal
      if (held_c && std::abs(*held_c - c) <= kMostHeldRad && near_enough(a, *held_c, planned))
        c = *held_c;
      else
        c = fewest(p.c_rad, [&](double candidate) { return near_enough(a, candidate, planned); });
      held_c = c;
    }
    p.a_rad = a;
    p.c_rad = c;
    const Eigen::Vector3d xyz =
        toolpath.moves[i].tip_mm + head.pivot_mm * (tool_axis_at(p.a_rad, p.c_rad, head) - Eigen::Vector3d::UnitZ());
    p.x_mm = xyz.x();
    p.y_mm = xyz.y();
    p.z_mm = xyz.z();
  }
  return poses;
}

}  // namespace lamina::post_detail
