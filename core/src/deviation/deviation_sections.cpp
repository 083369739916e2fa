// A layer's section at a height (Clipper, positive fill): the union of its outlines' edge rings.
#include "geometry/clipper_bridge.hpp"
#include "lamina/core/deviation.hpp"
#include "geometry/stack_geometry.hpp"

#include <algorithm>
#include <cmath>
#include <limits>


namespace lamina {

std::vector<Polygon2> layer_section(const LayerPlan& layer, double z_mm) {
  const double t = geometry_detail::layer_t(layer, z_mm);
  ClipperLib::Paths rings;
  for (const auto& outline : layer.outlines) {
    if (!geometry_detail::outline_usable(outline)) continue;
    Polygon2 ring = geometry_detail::edge_ring(outline, t);
    // A ring cut past itself keeps nothing: an outer no material, a hole no hole.
    if (geometry_detail::reversed_share(ring, geometry_detail::base_ring(outline)) > 0.5) continue;
    rings.push_back(geometry_detail::to_clipper(ring));
  }
  if (rings.empty()) return {};
  ClipperLib::Clipper clipper;
  clipper.AddPaths(rings, ClipperLib::ptSubject, true);
  ClipperLib::Paths out;
  clipper.Execute(ClipperLib::ctUnion, out, ClipperLib::pftPositive, ClipperLib::pftPositive);
  return geometry_detail::from_clipper(out);
}

}  // namespace lamina
