#pragma once
// Private: triangulation of one planar (or nearly planar) polygon given in 3D, used by the OBJ
// reader for faces with more than three corners.
#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <span>
#include <vector>

namespace lamina::geometry_detail {

// Reusable buffers so that a reader triangulating many polygons does not allocate per polygon.
struct EarClippingScratch {
  std::vector<double> x, y;
  std::vector<std::uint32_t> prev, next;
  std::uint64_t steps = 0;  // work so far: ear tests and the corners looked at in them
};

// Appends exactly corners.size() − 2 triangles (indices into `corners`, in the polygon's own
// winding) to `out`. The polygon is projected onto its best-fit plane (Newell normal) and cut by
// ear clipping, so non-convex simple polygons come out right. Degenerate input (collinear or
// self-intersecting) still yields n − 2 triangles: where no proper ear exists the most convex
// corner is cut, and a polygon with no area is fanned. Needs corners.size() ≥ 3.
//
// Faces of fewer than 64 corners are cut as they always were (each ear tested against every
// corner); larger ones in about n log n steps (triangulate_polygon_with_holes). False when a large
// face needed more than that clipper's step budget (2^20 + 32·n·log2 n, far beyond simple faces):
// the n − 2 triangles are still there but may overlap.
bool triangulate_polygon(std::span<const Eigen::Vector3f> corners, std::vector<std::array<std::uint32_t, 3>>& out,
                         EarClippingScratch& scratch);

}  // namespace lamina::geometry_detail
