#pragma once
// How far the layered part (as cut) is from the CAD model: the volume of their symmetric
// difference, integrated from Clipper XOR areas of fine horizontal sections, and the largest
// distance between the two surfaces.
#include "lamina/core/bevel.hpp"
#include "lamina/core/error.hpp"
#include "lamina/core/mesh.hpp"
#include "lamina/core/model_index.hpp"
#include "lamina/core/polygon.hpp"

#include <Eigen/Core>

#include <expected>
#include <memory>
#include <span>
#include <vector>

namespace lamina {

// The material a layer keeps at height z (z inside the layer): every outline's ring at that
// height, cleaned (self-overlaps and collapsed parts removed). Outer rings CCW, holes CW.
// A station's edge point is base + u·normal with u the lowest of its pass lines at z; the rings
// are united with positive winding (outer +1, hole −1), so a part of a ring the cuts turned
// backwards (a swallowtail at an inward corner, sides that crossed) keeps no material. A ring
// more than half of whose length runs against its outline (cut past its own axis, where it can
// come out wound the right way again) keeps nothing: an outer no material, a hole no hole.
std::vector<Polygon2> layer_section(const LayerPlan& layer, double z_mm);
// The same for some of its outlines (indices into layer.outlines; others ignored): one part's
// material, its outer outline and its holes.
std::vector<Polygon2> layer_section(const LayerPlan& layer, double z_mm, std::span<const int> outlines);

// More sections than this is a mistake in the parameters, not a finer answer (a 1e-5 mm step
// over the knob ran for minutes, issue 17 item 7): 0.05 mm over a metre, 1.5 µm over the knob.
inline constexpr double kMaxDeviationSections = 20'000;

struct DeviationParams {
  double step_mm = 0.1;             // spacing of the sections integrated over z
  double distance_sample_mm = 0.5;  // spacing of the surface points used for the largest distance
  bool parallel = true;
  // The measured mesh's triangle tree, when the caller has one (ignored for another mesh).
  std::shared_ptr<const ModelDistanceIndex> model_index;
};

struct Deviation {
  double model_volume_mm3 = 0.0;
  double stack_volume_mm3 = 0.0;
  double volume_mm3 = 0.0;   // symmetric difference
  double volume_pct = 0.0;   // of the model's volume
  double max_mm = 0.0;       // largest distance between stack and model surfaces (both ways)
  // Where it was found: the surface sample (on the stack or on the model) farthest from the other
  // surface.
  Eigen::Vector3d max_at_mm = Eigen::Vector3d::Zero();
};

// volume: sections every step_mm over the z range of both solids, each measured in the middle of
// its step (a step that a layer face crosses is split there, so bonding gaps and faces are
// integrated exactly); model sections from slice_mesh, stack sections from layer_section (empty
// in a bonding gap). max_mm: a sampled two-way (Hausdorff) distance: the stack's walls (stations
// at heights distance_sample_mm apart and where the envelope of their lines kinks, and points
// between stations) and its exposed faces (a layer's top where the next layer does not cover it,
// its bottom where the previous one does not: faces bonded to a neighbour are inside the part)
// against the model's triangles, and the model's vertices and facet centroids against the stack
// shells of stack_mesh. Both are independent of `parallel`.
// Errors: invalid_argument for a non-positive step or spacing, a layer without thickness, an
// outline with fewer than 3 stations or a pass without one line per station, a plan without any
// outline, or a spacing so fine it would take more than 5·10⁷ wall samples; empty_mesh.
std::expected<Deviation, Error> measure_deviation(const Mesh& mesh, const BevelPlan& plan,
                                                  const DeviationParams& params);

}  // namespace lamina
