#pragma once
// Plane ∩ mesh: closed contour loops made of contour vectors (paper section 3-2).
#include "lamina/core/error.hpp"
#include "lamina/core/mesh.hpp"

#include <Eigen/Core>

#include <cstdint>
#include <expected>
#include <functional>
#include <span>
#include <string>
#include <vector>

namespace lamina {

// The paper's contour vector, materialised: a segment of a slice contour with the facet it was
// cut from. Loops store points and facets compactly; Slice::vector() builds this record.
struct ContourVector {
  Eigen::Vector2d start_mm, end_mm;
  double z_mm = 0.0;
  std::int32_t facet = -1;          // -1 on a vector added by the gap rule (no facet behind it)
  Eigen::Vector3d normal;           // unit facet normal (horizontal gap normal when facet = -1)
  std::int32_t surface_id = -1;
};

struct Loop {
  // Vector i runs from points[i] to points[(i + 1) % n] and was cut from facets[i].
  std::vector<Eigen::Vector2d> points;
  std::vector<std::int32_t> facets;
  double area_mm2 = 0.0;   // signed: > 0 counter-clockwise (outer), < 0 clockwise (hole)
  int parent = -1;         // index of the innermost loop that encloses this one, -1 at top level
  int depth = 0;           // 0 for top-level outer loops, 1 for their holes, ...
  bool gap_closed = false; // built from open chains joined by the gap rule

  std::size_t size() const { return points.size(); }
  bool is_hole() const { return area_mm2 < 0.0; }
};

// A chain that did not close on itself (open mesh), before the gap rule.
struct OpenChain {
  std::vector<Eigen::Vector2d> points;  // n + 1 points for n vectors
  std::vector<std::int32_t> facets;
};

struct Slice {
  double z_mm = 0.0;
  std::vector<Loop> loops;               // outer loops CCW, holes CW; parent/depth give the tree
  std::vector<OpenChain> open_chains;    // as found, before the gap rule closed them
  std::vector<std::string> warnings;     // gap rule applied, union of overlapping shells, ...
  int outer_count() const;
  int hole_count() const;
  double net_area_mm2() const;
  ContourVector vector(const Mesh& mesh, std::size_t loop, std::size_t index) const;
};

struct SliceParams {
  // Open chains whose ends are within this distance are joined by a straight vector (facet -1).
  // 0 disables the gap rule: open chains are then only reported.
  double gap_close_mm = 1.0;
  // Slice on several threads (TBB); results do not depend on it.
  bool parallel = true;
};

// Cut the mesh at each height in zs (build frame, mm). Fails on an empty mesh or a non-finite z.
std::expected<std::vector<Slice>, Error> slice_mesh(const Mesh& mesh, std::span<const double> zs,
                                                    const SliceParams& params);

// The same slices handed to `visit(index into zs, slice)` as each is made, none kept: for callers
// that reduce each slice to a few numbers (the deviation's 1000 sections of the 1M sphere were
// ~90 MB at once). With params.parallel, visit is called from several threads at once.
std::expected<void, Error> for_each_slice(const Mesh& mesh, std::span<const double> zs, const SliceParams& params,
                                          const std::function<void(std::size_t, Slice&&)>& visit);

// More planes than this in one call is a mistake in the parameters (a 1e-9 mm step over 30 mm
// asked for 3·10^10 and died in std::bad_alloc, issue 17 item 7): slice_mesh refuses them.
inline constexpr std::size_t kMaxSlicePlanes = 100'000;

// How many planes heights_by_step gives (checked against kMaxSlicePlanes before making them).
double planes_by_step(double height_mm, double step_mm);

// Heights for "--step h": h/2, 3h/2, ... below the top (mid-layer planes avoid the flat ends).
// Empty for a step that gives more than kMaxSlicePlanes planes.
std::vector<double> heights_by_step(double height_mm, double step_mm);

}  // namespace lamina
