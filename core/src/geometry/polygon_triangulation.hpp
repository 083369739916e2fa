#pragma once
// Private: triangulation of a polygon with holes using exactly its vertices (no Steiner points,
// none dropped), so that a cap shares every edge with the walls it closes.
#include "lamina/core/polygon.hpp"

#include <array>
#include <cstdint>
#include <vector>

namespace lamina::geometry_detail {

// A corner turning with a smaller sine than this counts as straight when looking for ears:
// cutting it would leave a sliver that rounding to float (STL) can flatten to zero area.
inline constexpr double kCapStraightSine = 1e-7;

// What a triangulation cost, for callers that bound the work their input may ask for.
struct TriangulationWork {
  std::uint64_t steps = 0;  // ear tests, and the corners and grid cells looked at in them
  bool exhausted = false;   // the step budget ran out and the rest was cut corner by corner
};

// Vertices are numbered outer first, then each hole in order (hole h starts at
// outer.size() + sizes of holes before it). The outer ring should be counter-clockwise and the
// holes clockwise; a ring given the other way round is walked backwards. Holes must lie inside
// the outer ring and not overlap (rings with fewer than 3 points are ignored: their vertices are
// not used).
//
// Each hole is joined to the outer boundary by a bridge (Eberly: from the hole's rightmost vertex
// to a vertex visible along a ray to +x), holes taken right to left, then the merged ring is cut
// by ear clipping. A simple input gives n + 2h − 2 counter-clockwise triangles (n vertices, h
// holes) tiling it exactly. Degenerate input (collinear runs, coincident points, touching rings)
// still yields that many triangles and uses every boundary edge once, so a cap stays closed
// against its walls: where no proper ear exists the most convex corner is cut regardless.
//
// The work is about linear in n for simple rings and bounded by a step budget of
// 2^20 + 32·n·log2(n) for any ring: past it the rest is cut corner by corner (the same count and
// edges, but triangles that may overlap), and `work->exhausted` says so.
std::vector<std::array<std::int32_t, 3>> triangulate_polygon_with_holes(const Polygon2& outer,
                                                                        const std::vector<Polygon2>& holes,
                                                                        double straight_sine = kCapStraightSine,
                                                                        TriangulationWork* work = nullptr);

}  // namespace lamina::geometry_detail
