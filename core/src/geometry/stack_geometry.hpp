#pragma once
// Private: the edge the cuts of a bevel plan leave, shared by the sections (deviation), the stack
// mesh and the distance sampling. A station's edge at height z is the lower envelope of its pass
// lines, u(z) = min_p u_p(z), expressed as an offset along the station normal from its base point.
#include "lamina/core/bevel.hpp"
#include "lamina/core/deviation.hpp"
#include "lamina/core/mesh.hpp"
#include "lamina/core/polygon.hpp"

#include <polyclipping/clipper.hpp>

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <vector>

namespace lamina::detail {

// One station's pass lines as offsets along its normal: u(t) = bottom + t · (top − bottom),
// t = 0 at the layer's bottom face and 1 at its top face.
struct OffsetLine {
  double bottom = 0.0;
  double top = 0.0;
  double at(double t) const { return bottom + t * (top - bottom); }
};

// An outline usable as geometry: at least 3 stations, finite numbers, and every pass with one
// line per station. Outlines failing this are skipped by the geometry functions (and rejected by
// measure_deviation with a message).
bool outline_usable(const LayerOutline& outline);

// The lines of station s, as offsets. An outline without passes keeps its base outline (u = 0).
void station_lines(const LayerOutline& outline, std::size_t s, std::vector<OffsetLine>& out);

// min over the passes at t (0 without passes).
double station_offset(const LayerOutline& outline, std::size_t s, double t);

// Where the lower envelope of the lines changes line, t strictly inside (0, 1), increasing.
void envelope_kinks(const std::vector<OffsetLine>& lines, std::vector<double>& ts);

// t of height z in a layer (0 at the bottom face, 1 at the top; not clamped).
double layer_t(const LayerPlan& layer, double z_mm);

Polygon2 base_ring(const LayerOutline& outline);
Polygon2 edge_ring(const LayerOutline& outline, double t);

// Share of the base outline's length (by base edge) whose edge in `ring` runs backwards
// (dot < 0 with the base edge): the cuts overshot the outline there. A ring more than half
// reversed has collapsed through itself (an outline cut past its own axis keeps no material,
// though its ring can come out wound the right way, e.g. a circle shrunk past its centre).
double reversed_share(const Polygon2& ring, const Polygon2& base);

// The layer's outlines grouped as solids: an outer outline and the holes whose parent it is
// (only usable outlines; holes with a parent that is not a usable outer are left out).
struct OutlineGroup {
  int outer = -1;
  std::vector<int> holes;
};
std::vector<OutlineGroup> outline_groups(const LayerPlan& layer);

// The stack as closed triangle shells (double precision), one per layer outline group, wound
// outward. Built by stack_mesh.cpp; stack_mesh() converts it to a float soup, measure_deviation
// measures distances to it.
struct StackShells {
  std::vector<Eigen::Vector3d> vertices;
  std::vector<std::array<std::int32_t, 3>> faces;
  int shells = 0;
};
StackShells build_stack_shells(const BevelPlan& plan);

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

class TriangleTree;
// The sample farthest from the tree's triangles (the first of equals, in sample order).
FarthestPoint max_distance(const TriangleTree& tree, const std::vector<Eigen::Vector3d>& samples, bool parallel);

}  // namespace lamina::detail
