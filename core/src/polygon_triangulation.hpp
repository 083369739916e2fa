#pragma once
// Private: triangulation of a polygon with holes using exactly its vertices (no Steiner points,
// none dropped), so that a cap shares every edge with the walls it closes.
#include "lamina/core/polygon.hpp"

#include <array>
#include <cstdint>
#include <vector>

namespace lamina::detail {

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
std::vector<std::array<std::int32_t, 3>> triangulate_polygon_with_holes(const Polygon2& outer,
                                                                        const std::vector<Polygon2>& holes);

}  // namespace lamina::detail
