#pragma once
// Internal steps of slice_mesh, each in its own file; not part of the public API.
#include "lamina/core/slice.hpp"

#include <span>
#include <vector>

namespace lamina::slice_detail {

// The facets each plane cuts: plane p's are faces[offsets[p] .. offsets[p + 1]), ascending.
struct FacetBuckets {
  std::vector<std::int64_t> offsets;
  std::vector<std::int32_t> faces;
};
// `sorted_z` must be ascending. Runs in parallel (TBB); the result does not depend on it.
FacetBuckets bucket_facets(const Mesh& mesh, std::span<const double> sorted_z);

// Join open chains whose ends lie within gap_mm (greedy, nearest first) into loops whose joining
// vectors carry facet -1. Chains that cannot be closed stay in `chains` (they are reported).
// Returns the loops made; appends a warning line per slice to `warnings`.
std::vector<Loop> close_gaps(std::vector<OpenChain>& chains, double gap_mm,
                             std::vector<std::string>& warnings);

// Fill Loop::area_mm2 (signed shoelace).
void compute_area(Loop& loop);

// Fill parent/depth by containment (smallest enclosing loop).
void compute_nesting(std::vector<Loop>& loops);

// True when the loops do not form a consistent region: a CCW loop at odd depth, a CW loop at even
// depth, or two loops from different shells crossing each other.
bool needs_union(const std::vector<Loop>& loops, const std::vector<int>& loop_shell);

// Replace the loops by the boundary of the union of the solids they bound (positive winding),
// keeping each surviving piece's facet. Used where shells overlap.
std::vector<Loop> union_of_loops(const std::vector<Loop>& loops);

// Winding number of p with respect to one loop (0 outside, +1 inside CCW, -1 inside CW).
int winding_number(const Loop& loop, const Eigen::Vector2d& p);

}  // namespace lamina::slice_detail
