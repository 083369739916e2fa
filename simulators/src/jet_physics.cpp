#include "jet_physics.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace lamina::sim {

CutWall cut_wall(const JetPhysics& jet, double path_mm, double feed_mm_per_s) {
  const double v_s = jet.separation_mm_per_s_at_10mm * std::pow(10.0 / path_mm, jet.separation_exponent);
  const double r = std::max(feed_mm_per_s, 0.0) / v_s;
  CutWall wall;
  wall.top_width_mm = jet.focus_mm * (1.0 + jet.slow_widening * std::exp(-r / jet.slow_scale));
  const double lean = jet.taper_gain * std::pow(r, jet.taper_exponent) - jet.taper_offset;
  wall.wall_lean_tan = lean;
  // A wall cannot close the kerf: past that the jet no longer cuts through, and the slot is a groove.
  wall.bottom_width_mm = std::max(wall.top_width_mm - 2.0 * path_mm * lean, 0.0);
  const double lag_rad = jet.lag_max_deg * std::numbers::pi / 180.0 * (1.0 - std::exp(-jet.lag_rate * r * r));
  wall.trail_back_mm = path_mm * std::tan(lag_rad);
  return wall;
}

}  // namespace lamina::sim
