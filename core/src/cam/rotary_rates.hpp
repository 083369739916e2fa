#pragma once
// Feeds the head's rotary axes can follow (ToolpathParams::a_max_rad_per_s / c_max_rad_per_s).
#include "cam/toolpath_ring.hpp"

#include <vector>

namespace lamina::cam_detail {

// Lowers the feed of the lines of the closed path `points` where, at that feed, a move to or from
// a neighbour would turn A (the tilt) or C (the azimuth of a tilted axis; a vertical one holds C,
// post_axes.cpp) faster than its rate. A move takes its jet travel (the longer of the tip's and
// the bottom's) at the feed times its corner factor; both its lines are limited so that product
// fits. Returns how many lines were lowered.
std::size_t limit_feeds_to_rotary_rates(std::vector<PathPoint>& points, double a_max_rad_per_s, double c_max_rad_per_s);

}  // namespace lamina::cam_detail
