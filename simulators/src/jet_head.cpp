#include "jet_head.hpp"

#include <cmath>
#include <numbers>

namespace lamina::sim {
namespace {

using Vec = std::array<double, 3>;

// The vector v turned by `angle` about the unit axis k (Rodrigues).
Vec turned(const Vec& v, const Vec& k, double angle) {
  const double c = std::cos(angle), s = std::sin(angle);
  const double dot = k[0] * v[0] + k[1] * v[1] + k[2] * v[2];
  const Vec cross{k[1] * v[2] - k[2] * v[1], k[2] * v[0] - k[0] * v[2], k[0] * v[1] - k[1] * v[0]};
  Vec out{};
  for (int i = 0; i < 3; ++i) out[static_cast<std::size_t>(i)] = v[static_cast<std::size_t>(i)] * c + cross[static_cast<std::size_t>(i)] * s + k[static_cast<std::size_t>(i)] * dot * (1 - c);
  return out;
}

}  // namespace

JetPose jet_pose(const AxisValues& axes, const HeadGeometry& head) {
  constexpr double rad = std::numbers::pi / 180.0;
  const double c_turn = (head.c_sign * axes[4] + head.c_offset_deg) * rad;
  const double a_tilt = head.a_sign * axes[3] * rad;
  // The head's own x axis after C has turned it, then the jet tilted about it.
  const Vec head_x = turned({1, 0, 0}, {0, 0, 1}, c_turn);
  JetPose pose;
  pose.axis = turned({0, 0, 1}, head_x, a_tilt);
  for (int i = 0; i < 3; ++i) {
    const auto k = static_cast<std::size_t>(i);
    // The pivot sits pivot_mm up the axis from the tip; at A = 0 the program's point is the tip.
    const double rest = i == 2 ? head.pivot_mm : 0.0;
    pose.tip_mm[k] = head.rtcp ? axes[k] : axes[k] - (head.pivot_mm * pose.axis[k] - rest);
  }
  return pose;
}

}  // namespace lamina::sim
