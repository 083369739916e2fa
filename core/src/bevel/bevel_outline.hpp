#pragma once
// Private: the outline of a layer (the union of its sub-slices and the shadows between them,
// what a vertical outside cut keeps) and the stations along it (bevel.cpp plans each station's
// cuts). A finely tessellated outline is simplified off the material first (docs/bevels.md).
#include "geometry/clipper_bridge.hpp"
#include "lamina/core/polygon.hpp"
#include "lamina/core/slice.hpp"

#include <Eigen/Core>

#include <vector>

namespace lamina::bevel_detail {

struct OutlineRing {
  Polygon2 points;
  bool is_hole = false;
  int parent = -1;
  // Per corner: the edge to the next corner is a chord the simplification put in place of
  // corners (empty: none was).
  std::vector<char> chord;
};

// The union of every sub-slice's material and the shadows between them (`all`): outer rings
// CCW, holes CW, holes linked to their outer ring; holes narrower than min_hole_width_mm left
// closed. Each ring is simplified by simplify_mm (0: kept whole); `simplified` is set when one
// was.
std::vector<OutlineRing> layer_outline_rings(const std::vector<const Slice*>& sub_slices, ClipperLib::Paths all,
                                             double min_hole_width_mm, double simplify_mm, bool& simplified);

struct StationSeed {
  Eigen::Vector2d point, normal;
  // The cut from this station to the next runs along a chord of the outline's simplification,
  // and neither station is a sharp corner: a gouge there may be the simplification's.
  bool loose = false;
};

// Stations: every ring vertex (normal: bisector of its edges' normals) and extra points on edges
// longer than spacing_mm (normal: the edge's). Normals point out of the material.
std::vector<StationSeed> station_seeds(const OutlineRing& outline, double spacing_mm);

// The outline as a section, to find how far out a line may go before it meets other material
// of the same layer.
Slice outline_section(const std::vector<OutlineRing>& rings);

}  // namespace lamina::bevel_detail
