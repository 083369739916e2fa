#pragma once
// Private: the largest 3-D distance between one layer's cut edge and the model's surface in the
// layer's height (issue 17, item 4), what the tolerance checks.
#include "geometry/closest_point.hpp"
#include "lamina/core/bevel.hpp"
#include "lamina/core/slice.hpp"

#include <span>
#include <vector>

namespace lamina::bevel_detail {
using geometry_detail::TriangleTree;

// Both ways, on samples `ds_mm` apart: the layer's side walls (wall_samples) to the model's
// triangles, and the model's contours on the layer's sub-slices (every vertex and points between)
// to the layer's closed shell. A per-station check reads each station's vertical plane only and
// cannot see a surface that turns across the layer (a twisted prism's corners slide along the
// outline); this can. Faces are not sampled on the stack side: a layer's faces are surface only
// where its neighbours leave them exposed, which the layer alone does not know. Walls above the
// model's top or below its bottom (model_z_lo/hi_mm) are not sampled either: how far the stack
// ends from the model is the layering's to judge (StackEnd), not part of a layer's surface.
double layer_surface_distance(const TriangleTree& model, double model_z_lo_mm, double model_z_hi_mm,
                              const LayerPlan& layer, const std::vector<const Slice*>& sub_slices, double ds_mm);

}  // namespace lamina::bevel_detail
