#include "cam/toolpath_moves.hpp"

#include <algorithm>
#include <cmath>

namespace lamina::cam_detail {

void append_move(std::vector<ToolMove>& moves, ToolMove m, double max_turn_rad) {
  if (!moves.empty()) {
    const Eigen::Vector3d from_tip = moves.back().tip_mm, from_axis = moves.back().axis;
    const double turn = std::acos(std::clamp(from_axis.dot(m.axis), -1.0, 1.0));
    const auto pieces = static_cast<int>(std::ceil(turn / max_turn_rad - 1e-9));
    if (pieces > 1) {
      const double each_s = m.duration_s / pieces;
      for (int i = 1; i < pieces; ++i) {
        const double f = static_cast<double>(i) / pieces;
        ToolMove piece = m;
        piece.tip_mm = from_tip + (m.tip_mm - from_tip) * f;
        piece.axis = ((std::sin((1.0 - f) * turn) * from_axis + std::sin(f * turn) * m.axis) / std::sin(turn)).normalized();
        piece.duration_s = each_s;
        piece.dwell_s = 0.0;
        piece.turn_piece = true;
        moves.push_back(piece);
      }
      m.duration_s = each_s;
    }
  }
  moves.push_back(m);
}

void append_overlap(std::vector<PathPoint>& ring) {
  const double want_mm = ring.back().trail_back_mm;
  if (!(want_mm > 0.0)) return;
  const std::size_t closing = ring.size() - 1;  // ring[closing] is ring[0] again
  double run_mm = 0.0;
  for (std::size_t k = 1; k < closing && run_mm < want_mm; ++k) {
    const double step = (ring[k].tip - ring[k - 1].tip).norm();
    PathPoint q = ring[k];
    if (run_mm + step > want_mm) {  // the last one stops at the trail-back, on the line between
      const double f = (want_mm - run_mm) / step;
      q.tip = ring[k - 1].tip + f * (ring[k].tip - ring[k - 1].tip);
      q.bottom = ring[k - 1].bottom + f * (ring[k].bottom - ring[k - 1].bottom);
      q.axis = (q.tip - q.bottom).normalized();
      // A corner's slow-down reaches the new end only as far as its zone goes.
      if (std::isfinite(q.slow_zone_mm)) {
        q.slow_zone_mm -= (1.0 - f) * step;
        if (q.slow_zone_mm < 0.0) q.corner_factor = 1.0, q.slow_zone_mm = 0.0;
      }
    }
    run_mm += step;
    ring.push_back(q);
  }
}

}  // namespace lamina::cam_detail
