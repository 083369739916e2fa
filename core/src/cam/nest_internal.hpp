#pragma once
// Private: what the nesting driver (nest.cpp) asks of a packing method (nest_matrix.cpp,
// nest_shape.cpp). A method packs parts onto as many sheets of one size as it needs; the driver
// decides which sheets of the rack they become (stock order, counts, thin before thick).
#include "lamina/core/nest.hpp"

#include <Eigen/Core>

#include <span>
#include <vector>

namespace lamina::cam_detail {

// Spacing offsets and hole fits are made this much larger than asked, to cover libnest2d's 1 nm
// truncation of rotated points and our rounding of proxies and region corners to nm: footprints
// stay `spacing` apart and inside the margin.
inline constexpr double kSlackMm = 1e-5;

struct SheetSize {
  double length_mm = 0.0;  // x
  double width_mm = 0.0;   // y
};

// One packed sheet: placements in the order the method placed them.
struct PackedSheet {
  std::vector<Placement> placements;
};

struct ShapePackDiagnostics {
  // Largest distance (mm) between a vertex of the shape libnest2d reports for an item
  // (Item::transformedShape) and the same vertex mapped by the Placement we derived from it.
  double max_transform_error_mm = 0.0;
  int items = 0;
};

// R(angle) with exact entries at multiples of a quarter turn (so 90° maps grid points to grid points).
Eigen::Matrix2d rotation_matrix(double angle_rad);

// Axis-aligned bounds of a part's footprint rotated by angle (before any offset).
struct Bounds {
  Eigen::Vector2d min{0.0, 0.0};
  Eigen::Vector2d max{0.0, 0.0};
  double dx() const { return max.x() - min.x(); }
  double dy() const { return max.y() - min.y(); }
};
Bounds rotated_bounds(const Polygon2& ring, double angle_rad);

// The rotations a method may use: matrix 0 and 90°, shape NestParams::rotations_rad.
std::vector<double> method_rotations(const NestParams& params);

// Whether the part fits alone on an empty sheet of that size (footprint inside sheet minus margin)
// for at least one of the method's rotations.
bool fits_on_sheet(const Part& part, SheetSize size, const NestParams& params);

// Shelf packing of bounding boxes (paper's matrix layout). Every part in `which` must fit on an
// empty sheet (fits_on_sheet); one that does not is appended to `unplaced`. Returns the sheets in
// fill order.
std::vector<PackedSheet> pack_matrix(std::span<const Part> parts, std::span<const int> which, SheetSize size,
                                     const NestParams& params, std::vector<int>& unplaced);

// True-shape packing with libnest2d (NFP placer, first-fit selection). Every part in `which`
// must fit on an empty sheet. Parts libnest2d could not place at all are appended to `unplaced`.
std::vector<PackedSheet> pack_shape(std::span<const Part> parts, std::span<const int> which, SheetSize size,
                                    const NestParams& params, std::vector<int>& unplaced,
                                    ShapePackDiagnostics* diagnostics = nullptr);

// Hole filling (nest_holes.cpp), before packing: smaller parts of a thickness group go inside the
// free holes (Part::free_holes_mm) of larger ones, and travel with them onto whatever sheet the
// packer gives the host.
struct HostedPart {
  int host = -1;       // part index of the part in whose free hole it lies
  Placement in_host;   // in the host's layer XY: host_xy = R(rotation) · layer_xy + offset
};
struct HoleFilling {
  std::vector<HostedPart> hosted;  // in the order they were put in (hosts by decreasing area)
  std::vector<int> free;           // the group's parts in no hole, in group order: what gets packed
  int rejected_by_check = 0;       // positions the final check on real footprints refused (0 expected)
};
// Hosts by decreasing footprint area; each free hole by decreasing area; candidates by decreasing
// footprint area, at every rotation of the method, bottom-left in the hole's inner-fit region
// less the no-fit regions of the children already there. A hosted part may host in turn.
HoleFilling fill_holes(std::span<const Part> parts, std::span<const int> group, const NestParams& params);

// The child's sheet placement when its host is placed by `host`:
// R_h·(R_c·p + t_c) + t_h, i.e. rotation_h + rotation_c (in [0, 2π)) and offset R_h·t_c + t_h.
Placement compose(const Placement& host, const Placement& child_in_host);

}  // namespace lamina::cam_detail
