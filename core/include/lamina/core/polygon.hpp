#pragma once
// Plain 2-D polygons in mm: outer rings counter-clockwise, holes clockwise.
#include <Eigen/Core>

#include <vector>

namespace lamina {

using Polygon2 = std::vector<Eigen::Vector2d>;

// Signed area (shoelace): > 0 counter-clockwise.
double signed_area_mm2(const Polygon2& ring);

}  // namespace lamina
