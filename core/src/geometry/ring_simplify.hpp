#pragma once
// Private: fewer corners for a ring, on a chosen side of it (Clipper 6 paths, 1 unit = 1 nm).
// The nesting's proxies (cam/nest_fit.cpp) and the bevel planner's layer outlines, whose every
// corner would otherwise become a station (bevel.cpp), use the same one.
#include "geometry/clipper_bridge.hpp"

#include <numbers>
#include <vector>

namespace lamina::geometry_detail {

// A simple counter-clockwise ring `by_mm` beside a counter-clockwise ring, outside it when
// by_mm > 0 and inside when < 0: the ring offset by by_mm (mitred), then chords within |by| / 2,
// so every point of the result stands between |by| / 2 and 2 |by| off the ring, on that side.
// Corners of the offset ring that turn by more than keep_turn_rad stay. The ring itself when that
// fails (it splits, is not simple) or saves no corner.
ClipperLib::Path simplified_beside(const ClipperLib::Path& ring, double by_mm, double keep_turn_rad = std::numbers::pi);

// The same, saying which of its edges are chords that replaced corners: chord[i] for the edge
// from corner i to i + 1 (all 0 when the ring itself comes back).
struct SimplifiedRing {
  ClipperLib::Path ring;
  std::vector<char> chord;
};
SimplifiedRing simplified_beside_marked(const ClipperLib::Path& ring, double by_mm, double keep_turn_rad);

}  // namespace lamina::geometry_detail
