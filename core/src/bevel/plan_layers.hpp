#pragma once
// Private: planning layers over one mesh, for callers that plan many times over it (the
// layering's verification plans every layer it chooses, and thicker sheets beside them).
#include "bevel/facets_by_z.hpp"
#include "geometry/closest_point.hpp"
#include "lamina/core/bevel.hpp"
#include "lamina/core/slice.hpp"

#include <expected>
#include <span>
#include <vector>

namespace lamina::bevel_detail {
using geometry_detail::TriangleTree;

// What plan_bevels builds over the whole mesh before it plans a layer, built once by such
// callers; nullptr: built here. The facets must be binned at the params' sub_slice_mm.
struct MeshIndexes {
  const TriangleTree* model_tree = nullptr;  // read when params.measure_surface_distance
  const FacetsByZ* facets_by_z = nullptr;
};

// plan_bevels over the given indexes.
std::expected<BevelPlan, Error> plan_bevels_on(const Mesh& mesh, const MeshIndexes& indexes,
                                               std::span<const LayerSpan> layers, const BevelParams& params);

// Each layer planned on its own, as plan_bevels would plan it alone (layer i gets index i): the
// layers may overlap. Sliced in one pass, planned as one pool of tasks, the thickest first.
std::expected<std::vector<LayerPlan>, Error> plan_layers_apart(const Mesh& mesh, const MeshIndexes& indexes,
                                                               std::span<const LayerSpan> layers,
                                                               const BevelParams& params);

// One layer from its sub-slices (at heights zs), without the 3-D surface distance (bevel.cpp).
LayerPlan plan_layer(const Mesh& mesh, const FacetsByZ& facets_by_z, const LayerSpan& span, int index,
                     const std::vector<double>& zs, const std::vector<const Slice*>& sub_slices,
                     const BevelParams& params);

}  // namespace lamina::bevel_detail
