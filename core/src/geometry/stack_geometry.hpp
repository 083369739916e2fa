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

namespace lamina::geometry_detail {

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

}  // namespace lamina::geometry_detail
