// AC tilting head: forward and continuous inverse kinematics (see kinematics.hpp for the
// conventions). With θ = c_sign·C + c_offset and α = a_sign·A,
//   axis = Rz(θ)·Rx(α)·ẑ = (sin θ · sin α, −cos θ · sin α, cos α).
#include "lamina/core/kinematics.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

namespace lamina {

namespace {

constexpr double two_pi = 2.0 * std::numbers::pi;
constexpr double deg_per_rad = 180.0 / std::numbers::pi;
// A tilt this far past a limit is still within it: the limits come from degrees typed by a person,
// the tilt from an arc cosine; 1e-9 rad is 0.15 nm at the end of a 150 mm pivot.
constexpr double limit_slack_rad = 1e-9;
constexpr double unit_tolerance = 1e-6;  // |‖axis‖ − 1| allowed before the axis is "not a unit vector"

// The C + 2πk nearest to prev_c.
double nearest_turn(double c, double prev_c) { return c + two_pi * std::round((prev_c - c) / two_pi); }

bool within_a_limits(double a, const HeadKinematics& head) {
  return a >= head.a_min_rad - limit_slack_rad && a <= head.a_max_rad + limit_slack_rad;
}

}  // namespace

Eigen::Vector3d tool_axis_at(double a_rad, double c_rad, const HeadKinematics& head) {
  const double alpha = head.a_sign * a_rad;
  const double theta = head.c_sign * c_rad + head.c_offset_rad;
  const double s = std::sin(alpha);
  return {std::sin(theta) * s, -std::cos(theta) * s, std::cos(alpha)};
}

TipPose forward_kinematics(const AxisPose& pose, const HeadKinematics& head) {
  TipPose out;
  out.axis = tool_axis_at(pose.a_rad, pose.c_rad, head);
  const Eigen::Vector3d xyz(pose.x_mm, pose.y_mm, pose.z_mm);
  out.tip_mm = head.rtcp ? xyz : Eigen::Vector3d(xyz - head.pivot_mm * (out.axis - Eigen::Vector3d::UnitZ()));
  return out;
}

std::expected<AxisPose, Error> inverse_kinematics(const Eigen::Vector3d& tip_mm, const Eigen::Vector3d& axis,
                                                  double prev_c_rad, const HeadKinematics& head) {
  if (!tip_mm.allFinite() || !axis.allFinite() || !std::isfinite(prev_c_rad))
    return std::unexpected(Error{ErrorCode::invalid_argument, "tool tip, axis or previous C is not finite"});
  const double norm = axis.norm();
  if (std::abs(norm - 1.0) > unit_tolerance)
    return std::unexpected(Error{ErrorCode::invalid_argument,
                                 fmt::format("tool axis ({:.6g}, {:.6g}, {:.6g}) is not a unit vector (length {:.9g})",
                                             axis.x(), axis.y(), axis.z(), norm)});
  const Eigen::Vector3d u = axis / norm;
  const double tilt = std::acos(std::clamp(u.z(), -1.0, 1.0));  // α ≥ 0 of the first solution

  AxisPose pose;
  if (tilt < head.hold_c_below_rad) {
    // Vertical: every C gives the same axis; hold C so the head does not spin.
    pose.a_rad = 0.0;
    pose.c_rad = prev_c_rad;
  } else {
    const double theta = std::atan2(u.x(), -u.y());
    // The two solutions (α, θ) and (−α, θ + π), as machine A and C.
    const std::array<double, 2> alphas{tilt, -tilt};
    const std::array<double, 2> thetas{theta, theta + std::numbers::pi};
    bool found = false;
    double best_distance = 0.0;
    for (int i = 0; i < 2; ++i) {
      const double a = head.a_sign * alphas[i];
      if (!within_a_limits(a, head)) continue;
      const double c = nearest_turn(head.c_sign * (thetas[i] - head.c_offset_rad), prev_c_rad);
      const double distance = std::abs(c - prev_c_rad);
      if (!found || distance < best_distance) {
        found = true;
        best_distance = distance;
        pose.a_rad = a;
        pose.c_rad = c;
      }
    }
    if (!found)
      return std::unexpected(Error{
          ErrorCode::invalid_argument,
          fmt::format("tool axis needs a tilt of {:.3f} deg; A is limited to [{:.3f}, {:.3f}] deg", tilt * deg_per_rad,
                      head.a_min_rad * deg_per_rad, head.a_max_rad * deg_per_rad)});
  }

  const Eigen::Vector3d machine_axis = tool_axis_at(pose.a_rad, pose.c_rad, head);
  const Eigen::Vector3d xyz =
      head.rtcp ? tip_mm : Eigen::Vector3d(tip_mm + head.pivot_mm * (machine_axis - Eigen::Vector3d::UnitZ()));
  pose.x_mm = xyz.x();
  pose.y_mm = xyz.y();
  pose.z_mm = xyz.z();
  return pose;
}

}  // namespace lamina
