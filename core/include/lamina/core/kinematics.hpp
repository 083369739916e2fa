#pragma once
// 5-axis kinematics of an AC tilting head (DESIGN step 8). The tool axis (unit, tip → nozzle) at
// rotary positions A, C is
//   axis(A, C) = Rz(c_sign · C + c_offset) · Rx(a_sign · A) · ẑ
// and the head turns about a pivot pivot_mm up the tool axis from the tool tip. With RTCP on the
// controller (G43.4-style), the program carries the tip; otherwise it carries the pivot, shifted
// so that at A = 0 the machine's X Y Z equal the tip's: xyz = tip + pivot_mm · (axis − ẑ).
#include "lamina/core/error.hpp"

#include <Eigen/Core>

#include <expected>
#include <limits>

namespace lamina {

struct HeadKinematics {
  double pivot_mm = 150.0;
  int a_sign = 1;  // +1 or −1
  int c_sign = 1;
  double c_offset_rad = 0.0;
  double a_min_rad = -1.0471975511965976;  // ±60°
  double a_max_rad = 1.0471975511965976;
  double c_min_rad = -std::numeric_limits<double>::infinity();  // limited C: rewind in rapids
  double c_max_rad = std::numeric_limits<double>::infinity();
  double hold_c_below_rad = 1e-6;  // |A| below this: the axis is vertical, C is held (singularity)
  bool rtcp = true;                // the controller computes the pivot (G43.4); else we do
};

struct AxisPose {
  double x_mm = 0.0, y_mm = 0.0, z_mm = 0.0;
  double a_rad = 0.0, c_rad = 0.0;
};

Eigen::Vector3d tool_axis_at(double a_rad, double c_rad, const HeadKinematics& head);

// Forward: machine axes → tool tip and tool axis.
struct TipPose {
  Eigen::Vector3d tip_mm;
  Eigen::Vector3d axis;
};
TipPose forward_kinematics(const AxisPose& pose, const HeadKinematics& head);

// Inverse, continuous: of the two solutions (A, C) and (−A, C + π) — and every C + 2πk — the one
// within the A limits whose C is nearest prev_c_rad; at A ≈ 0, C = prev_c_rad. Errors when the
// axis needs more tilt than the A limits allow, or is not a unit vector.
std::expected<AxisPose, Error> inverse_kinematics(const Eigen::Vector3d& tip_mm, const Eigen::Vector3d& axis,
                                                  double prev_c_rad, const HeadKinematics& head);

}  // namespace lamina
