#pragma once
// The bevel plan of a layered part (paper 3-2 to 3-5): for every layer, its outlines, and on each
// outline the cut passes a 5-axis jet makes. A pass is a ruled surface: a closed sequence of jet
// lines (top point, bottom point), one per station of the outline.
#include "lamina/core/bevel_profile.hpp"
#include "lamina/core/error.hpp"
#include "lamina/core/layering.hpp"
#include "lamina/core/mesh.hpp"

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <expected>
#include <span>
#include <functional>
#include <vector>

namespace lamina {

// One jet line through the sheet, with everything downstream needs about it.
struct CutLine {
  Eigen::Vector3d top_mm;       // where the line leaves the sheet's top face (z = layer top)
  Eigen::Vector3d bottom_mm;    // where it leaves the bottom face (z = layer bottom)
  Eigen::Vector3d tool_axis;    // unit, from the tool tip towards the nozzle (bottom → top)
  double tilt_rad = 0.0;        // angle between tool axis and +Z, in [0, tilt_max]
  double c_rad = 0.0;           // atan2 of the axis' XY part, unwound along the pass (no 2π jumps);
                                // held from the previous line where tilt ≈ 0
  // The paper's eq. 1, kept for reference: V = N × C (outer loops; C × N on holes, which it orders
  // CCW too) is the surface tangent across the contour, pointing up; A = 180° − ∠(Z, V),
  // C = ∠(X, V) in the XY plane, here from atan2 (signed, −180°…180°), not acos.
  Eigen::Vector3d paper_v;      // unit; zero where the station has no facet behind it
  double paper_a_deg = 0.0;
  double paper_c_deg = 0.0;
};

// A point of a layer outline where the cuts are evaluated.
struct CutStation {
  Eigen::Vector2d base_mm;     // on the outline (the vertical "outside" edge: union of sub-slices)
  Eigen::Vector2d normal;      // unit, horizontal, out of the material
  ProfileShape shape = ProfileShape::empty;
  bool slope_rule_agrees = true;
  bool tilt_limited = false;
  std::int32_t surface_id = -1;  // surface of the model the top-most sample lies on
  double max_deviation_mm = 0.0;
};

struct CutPass {
  std::vector<CutLine> lines;  // one per station, same order; the pass is closed (last → first)
};

// One closed outline of a layer: an outer boundary (CCW) or a hole (CW).
struct LayerOutline {
  bool is_hole = false;
  int parent = -1;                    // for a hole: index of its outer outline in the layer
  std::vector<CutStation> stations;
  // Trim passes first, the pass that frees the part last. Every pass has one line per station.
  std::vector<CutPass> passes;
  double max_deviation_mm = 0.0;
};

struct LayerPlan {
  int index = 0;
  double z_bottom_mm = 0.0;
  double thickness_mm = 0.0;
  std::vector<double> sub_slice_z_mm;   // the thin slices the layer's profiles were read from
  std::vector<LayerOutline> outlines;   // outers and their holes (parent links)
  int passes = 0;                       // largest pass count of its outlines
  // What the tolerance checks (issue 17, item 4): the largest 3-D distance between the edge the
  // cuts leave and the model's surface in the layer's height (surface_distance_mm) when the
  // plan measured it (BevelParams::measure_surface_distance), else the profile-plane deviation.
  double max_deviation_mm = 0.0;
  double profile_deviation_mm = 0.0;    // largest station deviation, in each station's profile plane
  double surface_distance_mm = -1.0;    // sampled two-way 3-D distance (-1: not measured)
  bool within_tolerance = true;
  // Outside cuts moved off material their chords took between stations (issue 17, item 1: a
  // sharp corner on a sloped face): the largest move of a station, and the deepest sub-slice
  // material still outside the cuts afterwards (0 when all was cleared). Both mm.
  double gouge_shift_mm = 0.0;
  double gouge_left_mm = 0.0;
  // The outline lost corners to BevelParams::outline_simplify_mm (its stations are fewer than
  // the sections' corners).
  bool outline_simplified = false;
  // Stations per shape, indexed by ProfileShape.
  std::array<int, 5> shape_counts{};

  double z_top_mm() const { return z_bottom_mm + thickness_mm; }
};

struct BevelParams {
  ProfileFitParams fit;
  double sub_slice_mm = 0.5;        // spacing of the thin slices inside a layer (paper's thin layers)
  double station_spacing_mm = 1.0;  // outline edges longer than this get extra stations
  // The layer outline, whose corners are stations, loses corners within this (Douglas–Peucker on
  // the outline grown by it): its rings then stand between half and twice this off the material.
  // 0 keeps every corner of the model's sections.
  double outline_simplify_mm = 0.01;
  double tolerance_mm = 0.1;        // within_tolerance threshold for max_deviation_mm
  // Holes of a layer outline narrower than this (mean width 2·area/perimeter) stay closed: a
  // jet cannot cut them, and they are mostly slivers where sub-slices nearly coincide.
  double min_hole_width_mm = 0.1;
  // Measure each layer's 3-D distance to the model (LayerPlan::surface_distance_mm), sampled
  // distance_sample_mm apart; off for plans only their geometry is wanted of.
  bool measure_surface_distance = true;
  double distance_sample_mm = 0.5;
  bool parallel = true;             // layers on several threads (TBB); results do not depend on it
  // Called once for each layer planned, from the planning threads (it must be safe to call from
  // several at once): a progress bar's steps.
  std::function<void()> on_layer;
};

struct BevelPlan {
  std::vector<LayerPlan> layers;
  ProfileFitParams fit;
};

// Plan the cuts of every layer. Layers must be non-overlapping and in increasing z.
std::expected<BevelPlan, Error> plan_bevels(const Mesh& mesh, std::span<const LayerSpan> layers,
                                            const BevelParams& params);

// The sub-slice heights of a layer: both faces nudged 1 µm inwards (so flat faces of the model
// that coincide with a layer face are read from the right side) and evenly spaced inner slices
// no further apart than sub_slice_mm.
std::vector<double> sub_slice_heights(double z_bottom_mm, double thickness_mm, double sub_slice_mm);

}  // namespace lamina
