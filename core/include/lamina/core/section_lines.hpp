#pragma once
// Line queries against one slice: where does a horizontal line cross the section's boundary?
// Used to find the corresponding points of a station on every sub-slice of a layer (paper 3-4:
// "a line parallel to the projected vector … intersected with a short list of line segments").
#include "lamina/core/box_grid.hpp"
#include "lamina/core/mesh.hpp"
#include "lamina/core/slice.hpp"

#include <Eigen/Core>

#include <cstdint>
#include <optional>
#include <vector>

namespace lamina {

struct LineCrossing {
  double u_mm = 0.0;            // position along the line: origin + u·direction
  Eigen::Vector3d normal;       // unit facet normal of the contour vector crossed
  std::int32_t surface_id = -1;
  std::int32_t facet = -1;
};

enum class CrossingPick : std::uint8_t {
  largest,       // the exit crossing with the largest u in range (first met walking in from u_max)
  nearest_zero,  // the exit crossing with the smallest |u| in range
};

// A uniform grid over one slice's contour vectors. Cheap to build (linear in the slice size),
// immutable afterwards, safe to query from several threads.
// Which queries a SectionLines is built for: contains() has its own, finer grid (a cell of a
// couple of contour vectors: the crossings' grid holds ~√n vectors in each cell a contour
// passes), built only when asked for.
enum class SectionQueries : std::uint8_t { crossings, crossings_and_contains };

class SectionLines {
 public:
  SectionLines() = default;
  SectionLines(const Mesh& mesh, const Slice& slice, SectionQueries queries = SectionQueries::crossings);

  double z_mm() const { return z_mm_; }
  bool empty() const { return segments_.empty(); }

  // Exit crossings of the line origin + u·direction (direction: unit, horizontal) with u in
  // [u_min, u_max]: places where, walking towards +u, one leaves the material. Material is on
  // the left of every loop vector (outer loops CCW, holes CW), so this is independent of which
  // loop is crossed.
  std::optional<LineCrossing> exit_crossing(const Eigen::Vector2d& origin, const Eigen::Vector2d& direction,
                                            double u_min, double u_max, CrossingPick pick) const;

  // True when p lies inside the section's material (even-odd over all loops), or on its
  // boundary (the section is closed). From the answer at the centre of p's cell, kept for every
  // cell, and the contour vectors of that cell that the segment centre → p crosses. Built
  // without SectionQueries::crossings_and_contains it tests every vector.
  bool contains(const Eigen::Vector2d& p) const;

 private:
  // 40 bytes: a crossing's normal and surface come from the mesh when it is returned, not kept
  // for every vector (64 bytes with them; the layering's sub-slices of the 1M sphere held ~50 MB).
  struct Segment {
    Eigen::Vector2d a, b;
    std::int32_t facet;
  };
  LineCrossing crossing_at(std::size_t index, double u_mm) const;
  const Mesh* mesh_ = nullptr;  // outlives the lines (every user keeps both)
  double z_mm_ = 0.0;
  std::vector<Segment> segments_;
  BoxGrid grid_;  // cell → indices into segments_
  BoxGrid inside_grid_;                      // contains(): cell → indices into segments_
  std::vector<std::uint8_t> centre_inside_;  // per cell of inside_grid_: its centre is material
  void build_inside_grid(const std::vector<Box2>& boxes);
};

// du/dz of a surface with unit normal `normal` in the vertical plane along the horizontal unit
// direction `direction`: the facet plane's trace in the profile plane. Clamped to ±1e6
// (horizontal facets).
double profile_slope(const Eigen::Vector3d& normal, const Eigen::Vector2d& direction);

}  // namespace lamina
