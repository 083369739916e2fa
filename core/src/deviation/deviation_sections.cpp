// A layer's section at a height (Clipper, positive fill): the union of its outlines' edge rings.
#include "geometry/clipper_bridge.hpp"
#include "lamina/core/deviation.hpp"
#include "geometry/stack_geometry.hpp"

#include <algorithm>
#include <cmath>
#include <limits>


namespace lamina {

namespace {

std::vector<Polygon2> outlines_section(const LayerPlan& layer, double z_mm, const std::vector<const LayerOutline*>& outlines) {
  const double t = geometry_detail::layer_t(layer, z_mm);
  ClipperLib::Paths rings;
  for (const LayerOutline* o : outlines) {
    const LayerOutline& outline = *o;
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

}  // namespace

std::vector<Polygon2> layer_section(const LayerPlan& layer, double z_mm) {
  std::vector<const LayerOutline*> all;
  for (const auto& outline : layer.outlines) all.push_back(&outline);
  return outlines_section(layer, z_mm, all);
}

std::vector<Polygon2> layer_section(const LayerPlan& layer, double z_mm, std::span<const int> outlines) {
  std::vector<const LayerOutline*> some;
  for (const int i : outlines)
    if (i >= 0 && static_cast<std::size_t>(i) < layer.outlines.size()) some.push_back(&layer.outlines[static_cast<std::size_t>(i)]);
  return outlines_section(layer, z_mm, some);
}

}  // namespace lamina
