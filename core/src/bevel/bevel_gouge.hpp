#pragma once
// Private: keeping an outside-cut layer's ruled surfaces off the model's material (issue 17,
// item 1). Each station's lines fit the profile in the station's own vertical plane; between
// two stations the cut runs along the chord of their lines, and where a sub-slice's corner
// moves sideways across the layer (a sharp convex corner on a sloped face) that chord passes
// inside the corner: the jet takes part material. The check is made on the sub-slices the
// profiles were read from, and the two stations of a chord that cuts a corner are moved out
// along their normals until no sub-slice material lies outside the layer's section.
#include "lamina/core/bevel.hpp"
#include "lamina/core/section_lines.hpp"
#include "lamina/core/slice.hpp"

#include <vector>

namespace lamina::bevel_detail {

struct GougeClearance {
  double worst_found_mm = 0.0;  // deepest sub-slice material outside the cuts before clearing
  double worst_left_mm = 0.0;   // and after (0 unless a station reached max_shift_mm)
  int stations_moved = 0;
  double largest_shift_mm = 0.0;
  int moves_undone = 0;  // moves that would have entered other material (left as they were)
  // The deepest found before clearing on a chord between two stations the caller marks (0 when
  // it marks none).
  double worst_found_loose_mm = 0.0;
};

// Moves lines of `layer` (outside cuts only) so that every sub-slice's material lies inside the
// layer's section at the sub-slice's height, within kGougeTolerance; a station moves at most
// max_shift_mm. Each moved station's max_deviation_mm grows by its shift. `lines` are the
// sub-slices' section lines, in the same order, built with their containment grid. `marked`
// (per outline, per station: the chord to the next station) chooses the chords whose gouges
// worst_found_loose_mm reports.
GougeClearance clear_gouges(LayerPlan& layer, const std::vector<const Slice*>& sub_slices,
                            const std::vector<SectionLines>& lines, double max_shift_mm,
                            const std::vector<std::vector<char>>* marked = nullptr);

// Material deeper than this outside the cuts counts as a gouge (the Clipper grid is 1 nm, the
// mesh is float).
inline constexpr double kGougeTolerance = 1e-4;

}  // namespace lamina::bevel_detail
