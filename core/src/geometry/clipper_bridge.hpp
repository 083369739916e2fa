#pragma once
// Private: between our polygons (double mm) and Clipper 6's integer paths. One scale for the
// whole library: 1 unit = 1 nm, so ±4.6e9 m of range and far below any mesh's float precision.
#include "lamina/core/polygon.hpp"
#include "lamina/core/slice.hpp"

#include <polyclipping/clipper.hpp>

#include <vector>

namespace lamina::geometry_detail {

inline constexpr double kClipperUnitsPerMm = 1e6;

ClipperLib::Path to_clipper(const Polygon2& ring);
ClipperLib::Paths to_clipper(const std::vector<Polygon2>& rings);
Polygon2 from_clipper(const ClipperLib::Path& path);
std::vector<Polygon2> from_clipper(const ClipperLib::Paths& paths);

// Net signed area of paths in mm² (holes count negative).
double area_mm2(const ClipperLib::Paths& paths);

// A slice's material as paths a boolean can read with the positive rule. The slicer's loops do
// not cross (it unites shells that overlap) and are oriented outer counter-clockwise, holes
// clockwise: they are taken as they are. Loops closed by the gap rule (an open mesh) may cross:
// those slices are united first. (Uniting every slice was a full Clipper pass per section, a third
// of the 1M sphere's deviation sections.)
ClipperLib::Paths slice_material(const Slice& slice);

// A boolean of two regions read with the non-zero rule (outer rings CCW, holes CW).
ClipperLib::Paths boolean(ClipperLib::ClipType op, const ClipperLib::Paths& subject, const ClipperLib::Paths& clip);

// Offset with mitred joins (squared beyond Clipper's limit 2): every point the offset moves the
// boundary past is at least |delta| away, i.e. a superset of the true (round) growth and, for a
// negative delta, a subset of the true erosion.
ClipperLib::Paths offset_mitre(const ClipperLib::Paths& paths, double delta_mm);

}  // namespace lamina::geometry_detail
