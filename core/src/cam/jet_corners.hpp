#pragma once
// Corner speeds from the jet's trail-back (issue 20, docs/jet.md): where the path turns, the
// jet's lower part, lagging the nozzle by the trail-back L, cuts across the turn instead of
// following it. Its error is bounded by the chord between the path L before and L after:
// e = L · sin(θ/2), θ the path's turn within that window (a sharp corner: its angle; a circle of
// radius R: 2L/R). Where e exceeds the allowance, the feed drops until the model's lag at that
// feed keeps e within it, and stays down for the full feed's lag either side of the point, so
// the lag has settled before the turn and the jet's bottom has come round it before the feed
// rises again. Without a kerf model the toolpath keeps its angle heuristic (mark_corners).
#include "lamina/core/error.hpp"
#include "lamina/core/kerf.hpp"
#include "lamina/core/toolpath.hpp"
#include "cam/toolpath_ring.hpp"

#include <expected>
#include <span>
#include <vector>

namespace lamina::cam_detail {

struct JetCornerInput {
  const KerfModel* kerf = nullptr;
  double thickness_mm = 0.0;
  JetCorners corners;  // the allowance, the floor and the inside-corner strategy
  bool part_on_right = true;  // the path's side convention (ToolpathParams): the scrap is on the other
};

// Sets corner_factor and slow_zone_mm of every point of the closed path `points` (their feeds
// set, separation_mm_per_s[i] the separation speed of line i). Returns how many points the floor
// (corners.min_fraction) held above the speed the allowance asked for. Errors name the point.
std::expected<std::size_t, Error> jet_corner_speeds(std::vector<PathPoint>& points, std::span<const double> separation_mm_per_s,
                                                    const JetCornerInput& in);

}  // namespace lamina::cam_detail
