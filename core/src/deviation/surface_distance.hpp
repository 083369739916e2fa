#pragma once
// Distances between the stack's surface and the model's, on samples (deviation_distance.cpp).
// The bevel's per-layer check (bevel/bevel_distance.cpp) samples the same way.
#include <vector>

#include <Eigen/Core>
#include <polyclipping/clipper.hpp>

#include "geometry/closest_point.hpp"
#include "geometry/stack_geometry.hpp"

namespace lamina::deviation_detail {
using geometry_detail::Threads;
using geometry_detail::TriangleTree;

// The largest distance between the stack's surface and the model's (both ways), estimated on
// samples: the stack's walls (stations at heights no further apart than
// params.distance_sample_mm, where the envelope of their lines kinks, and along the outline
// between stations) and its exposed faces (each layer's top and bottom where the neighbouring
// layer does not cover it) against the model's triangles; the model's vertices and facet
// centroids against the stack shells. Needs a plan that passed measure_deviation's checks.
struct FarthestPoint {
  double distance = 0.0;
  Eigen::Vector3d at = Eigen::Vector3d::Zero();
};
FarthestPoint max_surface_distance(const Mesh& mesh, const BevelPlan& plan, const DeviationParams& params);

// Points on a layer's side walls (the edge its cuts leave): rows no more than ds apart from face
// to face, where the envelope of a station's lines kinks, and along the outline between stations.
void wall_samples(const LayerPlan& layer, double ds, std::vector<Eigen::Vector3d>& out);

// Samples of a horizontal region (Clipper paths, positive fill) at height z: its vertices, its
// edges every `spacing` and the points of a `spacing` grid inside it (coarser when the grid would
// exceed `budget` points).
void sample_region(const ClipperLib::Paths& region, double z, double spacing, double budget,
                   std::vector<Eigen::Vector3d>& out);

// The sample farthest from the tree's triangles (the first of equals, in sample order).
FarthestPoint max_distance(const TriangleTree& tree, const std::vector<Eigen::Vector3d>& samples, Threads threads);

}  // namespace lamina::deviation_detail
