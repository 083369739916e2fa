#pragma once
// The simulated machine's jet (issue 20): the kerf it really leaves, from what it executes —
// the "real machine" the planner must learn through calibration. Deliberately not the planner's
// form (kerf.hpp: linear top width, taper linear in the feed ratio, trail-back a power law):
//   separation speed   v_s(h) = v_s10 · (10 mm / h)^β
//   top width          w_t = d · (1 + g · exp(−r / s))          (wider when slow: more dwell)
//   each wall's lean   tan θ = k · r^n − k0                     (reversed below (k0/k)^(1/n))
//   bottom width       w_b = w_t − 2 h tan θ
//   trail-back         lag = h · tan(φ_max · (1 − exp(−λ r²)))  (saturates: the jet bends, not breaks)
// with r = v / v_s(h). Coefficients in the simulator's machine file (jet_* keys, docs/simulator.md).
#include <string>
#include <vector>

namespace lamina::sim {

struct JetPhysics {
  double separation_mm_per_s_at_10mm = 25.0;
  double separation_exponent = 1.2;
  double focus_mm = 0.95;
  double slow_widening = 0.15;
  double slow_scale = 0.3;
  double taper_gain = 0.035;
  double taper_exponent = 1.5;
  double taper_offset = 0.004;
  double lag_max_deg = 25.0;
  double lag_rate = 1.3;
};

struct CutWall {
  double top_width_mm = 0.0, bottom_width_mm = 0.0, trail_back_mm = 0.0;
  // tan θ of each wall from the jet's axis, as the physics gives it: where the walls would meet
  // above the bottom (w_t / (2 tan θ) < the path), the jet stops there and bottom_width_mm is 0.
  double wall_lean_tan = 0.0;
};

// The kerf of a straight cut crossing `path_mm` of material at `feed_mm_per_s`.
CutWall cut_wall(const JetPhysics& jet, double path_mm, double feed_mm_per_s);

}  // namespace lamina::sim
