#pragma once
// Two rules of how a sheet's moves go out (toolpath.cpp), each with its reason:
// - append_move: no move turns the jet's axis by more than ToolpathParams::max_turn_per_move_rad
//   (a pivot head without RTCP interpolates its joints: its tip would leave the line);
// - append_overlap: a ring that frees a part runs on past its start by the jet's trail-back.
#include "cam/toolpath_ring.hpp"
#include "lamina/core/toolpath.hpp"

#include <vector>

namespace lamina::cam_detail {

// Appends `m`, in pieces when its axis turns more than `max_turn_rad` from the last move's: the
// tip along its line, the axis by slerp, the time shared, all pieces but the last marked
// turn_piece (only the last keeps the dwell).
void append_move(std::vector<ToolMove>& moves, ToolMove m, double max_turn_rad);

// `ring` is closed (its last point is its first). Known under jet compensation (trail_back_mm of
// its last point; none without it, so those programs are as before): the jet's lower part lags
// the nozzle, and a lead-out straight from the start would leave the bottom of the ring's last
// stretch uncut, a tab that holds the part. Appends the ring's points again from its start up to
// exactly that length (the last one interpolated).
void append_overlap(std::vector<PathPoint>& ring);

}  // namespace lamina::cam_detail
