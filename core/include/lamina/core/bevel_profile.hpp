#pragma once
#include "lamina/core/choices.hpp"
// The cut lines of one station of a layer, in the station's profile plane (paper 3-3 to 3-5).
//
// A station is a point on a layer's outline with a horizontal outward unit normal n. The profile
// plane is the vertical plane through the station containing n; in it a point is (z, u): height
// and offset along n. The model's surface crosses the plane as a curve; on sub-slice j it sits at
// u_j, and the part's material is on the side u < u_j. A cut is a straight jet line through the
// sheet, u(z) linear between the layer's bottom and top; several cuts keep the intersection of
// their material sides, so the edge left at height z is the *minimum* of the cut lines there.
//
// Pure 1-D geometry: everything that needs the mesh (finding the samples) lives in bevel.cpp.
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

namespace lamina {

// Which side of the surface a cut may lie on (Hope et al.): outside never removes part
// material (default); inside never leaves material beyond the surface; mixed straddles it.
enum class CutSide : std::uint8_t { outside, inside, mixed };

// How a layer's edge is cut: curved form (the paper's method), one sloped ruled chord per
// station, or vertical edges (classic layered manufacturing).
enum class BevelStrategy : std::uint8_t { curved, sloped, vertical };

// Shape of the surface across a layer at a station (paper 3-4). convex: the surface bulges out
// of the chord between its top and bottom points (needs several tangent cuts); concave: it
// stays behind the chord (one chord cut). mixed: both (an inflection). empty: no sample.
enum class ProfileShape : std::uint8_t { straight, convex, concave, mixed, empty };

// Registered choices (choices.hpp): "outside", "inside", "mixed"; "curved", "sloped", "vertical".
const ChoiceTable<CutSide>& cut_sides();
const ChoiceTable<BevelStrategy>& bevel_strategies();
const char* cut_side_name(CutSide side);
const char* bevel_strategy_name(BevelStrategy strategy);
const char* profile_shape_name(ProfileShape shape);

struct ProfileSample {
  double z_mm = 0.0;       // sub-slice height
  double u_mm = 0.0;       // where the surface crosses the station's line on that sub-slice
  double slope = 0.0;      // du/dz of the surface there, from the facet normal (tangent)
  bool present = false;    // false: the sub-slice has no material on this line near the station
};

// A jet line through the sheet: u linear from u_bottom_mm at z_bottom to u_top_mm at z_top.
struct CutLine1D {
  double u_bottom_mm = 0.0;
  double u_top_mm = 0.0;
};

struct ProfileFitParams {
  CutSide side = CutSide::outside;
  BevelStrategy strategy = BevelStrategy::curved;
  double tilt_max_rad = 1.0471975511965976;  // 60°: the machine's A-axis limit
  // Profiles within this distance of their chord are straight (float noise of the mesh).
  double straight_tolerance_mm = 1e-3;
};

struct ProfileFit {
  ProfileShape shape = ProfileShape::empty;
  // The paper's θ-vs-β rule (tangent at the bottom steeper than at the top → convex) gave the
  // same class as the chord-offset rule. Only meaningful for convex/concave.
  bool slope_rule_agrees = true;
  // Convex spans cut with the curved form: one line per sample (sub-slice), in sample order;
  // a sample without material reuses its nearest neighbour's line. Otherwise one line.
  std::vector<CutLine1D> cuts;
  bool tilt_limited = false;      // a line was held at the tilt limit (supporting cut)
  // Largest distance, in the profile plane, between the edge left by the cuts and the surface
  // (both directions: cut edge to surface and surface to cut edge), mm.
  double max_deviation_mm = 0.0;
};

// A point of the model's surface in the profile plane (the trace of a facet): outside cuts must
// pass at or beyond every such point, so they clear the surface between sub-slices too.
struct ProfileBound {
  double z_mm = 0.0;
  double u_mm = 0.0;
};

// Classify the profile and choose its cut lines for the given side, strategy and tilt limit.
// samples are in increasing z between z_bottom_mm and z_top_mm (inclusive). Without bounds, the
// corners of neighbouring tangents stand in for the surface between samples. No line may go
// beyond u_ceiling_mm (the next material of the layer out along the station's normal: another
// island, the far side of a slot); such a line is replaced by the vertical supporting one.
ProfileFit fit_profile(std::span<const ProfileSample> samples, double z_bottom_mm, double z_top_mm,
                       const ProfileFitParams& params, std::span<const ProfileBound> bounds = {},
                       double u_ceiling_mm = std::numeric_limits<double>::infinity());

// The edge the cuts leave at height z: min over the lines (the intersection of their sides).
double cut_edge_at(const ProfileFit& fit, double z_mm, double z_bottom_mm, double z_top_mm);

}  // namespace lamina
