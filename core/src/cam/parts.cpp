// Parts of a bevel plan: each outer outline with its holes, the footprint nesting keeps clear, and
// registration dowels placed where every layer has material.
#include "lamina/core/parts.hpp"

#include "geometry/clipper_bridge.hpp"

#include <fmt/format.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace lamina {
namespace {

// The top and bottom rings of every pass of an outline: the ruled surfaces' traces on both faces.
ClipperLib::Paths pass_rings(const LayerOutline& outline) {
  ClipperLib::Paths rings;
  for (const CutPass& pass : outline.passes) {
    Polygon2 top, bottom;
    top.reserve(pass.lines.size());
    bottom.reserve(pass.lines.size());
    for (const CutLine& l : pass.lines) {
      top.emplace_back(l.top_mm.x(), l.top_mm.y());
      bottom.emplace_back(l.bottom_mm.x(), l.bottom_mm.y());
    }
    rings.push_back(geometry_detail::to_clipper(top));
    rings.push_back(geometry_detail::to_clipper(bottom));
  }
  return rings;
}

ClipperLib::Paths boolean(ClipperLib::ClipType op, const ClipperLib::Paths& a, const ClipperLib::Paths& b) {
  ClipperLib::Clipper c;
  c.AddPaths(a, ClipperLib::ptSubject, true);
  if (!b.empty()) c.AddPaths(b, ClipperLib::ptClip, true);
  ClipperLib::Paths out;
  // Rings of one outline may wind either way where the ruled surface folds; nonzero fill takes
  // what any of them encloses.
  c.Execute(op, out, ClipperLib::pftNonZero, ClipperLib::pftNonZero);
  return out;
}

ClipperLib::Paths offset(const ClipperLib::Paths& paths, double delta_mm) {
  if (delta_mm == 0.0) return paths;
  ClipperLib::ClipperOffset o;
  o.ArcTolerance = 0.005 * geometry_detail::kClipperUnitsPerMm;  // 5 µm: round joins stay few points
  o.AddPaths(paths, ClipperLib::jtRound, ClipperLib::etClosedPolygon);
  ClipperLib::Paths out;
  o.Execute(out, delta_mm * geometry_detail::kClipperUnitsPerMm);
  return out;
}

// The material a layer keeps for certain: inside every ring of its outers, outside every ring of
// its holes (the intersection over passes and both faces).
ClipperLib::Paths certain_material(const LayerPlan& layer) {
  ClipperLib::Paths material;
  for (const LayerOutline& o : layer.outlines) {
    if (o.is_hole) continue;
    ClipperLib::Paths kept;
    bool first = true;
    for (ClipperLib::Path& ring : pass_rings(o)) {
      if (ClipperLib::Area(ring) < 0) ClipperLib::ReversePath(ring);
      kept = first ? ClipperLib::Paths{ring} : boolean(ClipperLib::ctIntersection, kept, {ring});
      first = false;
    }
    material = boolean(ClipperLib::ctUnion, material, kept);
  }
  ClipperLib::Paths holes;
  for (const LayerOutline& o : layer.outlines)
    if (o.is_hole)
      for (ClipperLib::Path& ring : pass_rings(o)) {
        if (ClipperLib::Area(ring) < 0) ClipperLib::ReversePath(ring);
        holes.push_back(std::move(ring));
      }
  return holes.empty() ? material : boolean(ClipperLib::ctDifference, material, holes);
}

bool inside(const ClipperLib::Paths& region, const Eigen::Vector2d& p) {
  const ClipperLib::IntPoint q(static_cast<ClipperLib::cInt>(std::llround(p.x() * geometry_detail::kClipperUnitsPerMm)),
                               static_cast<ClipperLib::cInt>(std::llround(p.y() * geometry_detail::kClipperUnitsPerMm)));
  int winding = 0;
  for (const ClipperLib::Path& ring : region) {
    const int in = ClipperLib::PointInPolygon(q, ring);
    if (in != 0) winding += ClipperLib::Orientation(ring) ? 1 : -1;
  }
  return winding > 0;
}


}  // namespace

std::string part_label(const Part& part) { return fmt::format("L{}-{}", part.layer, part.island); }

std::expected<std::vector<Eigen::Vector2d>, Error> place_dowels(const BevelPlan& plan, const DowelParams& params) {
  if (params.count == 0) return std::vector<Eigen::Vector2d>{};
  if (params.count < 0 || params.count > 64)
    return std::unexpected(invalid_argument(fmt::format("dowels: count {} is outside 0 … 64", params.count)));
  if (!(params.diameter_mm > 0.0) || !std::isfinite(params.diameter_mm))
    return std::unexpected(invalid_argument(fmt::format("dowels: diameter {} mm must be > 0", params.diameter_mm)));
  if (!(params.wall_mm >= 0.0) || !std::isfinite(params.wall_mm))
    return std::unexpected(invalid_argument(fmt::format("dowels: wall {} mm must be >= 0", params.wall_mm)));
  if (plan.layers.empty()) return std::unexpected(invalid_argument("dowels: the plan has no layers"));

  // Where every layer has material, shrunk so a hole of the dowel's radius keeps its wall.
  ClipperLib::Paths common;
  for (std::size_t i = 0; i < plan.layers.size(); ++i) {
    const ClipperLib::Paths m = certain_material(plan.layers[i]);
    common = i == 0 ? m : boolean(ClipperLib::ctIntersection, common, m);
    if (common.empty())
      return std::unexpected(invalid_argument(fmt::format(
          "dowels: no area has material in every layer (layers 0 … {} share none)", plan.layers[i].index)));
  }
  const double r = 0.5 * params.diameter_mm;
  // 1 µm more: the offset rounds to Clipper's 1 nm grid, and the wall must hold, not nearly hold.
  const ClipperLib::Paths room = offset(common, -(r + params.wall_mm + 1e-3));
  if (room.empty())
    return std::unexpected(invalid_argument(fmt::format(
        "dowels: no room for a {} mm dowel with a {} mm wall where every layer has material", params.diameter_mm,
        params.wall_mm)));

  // Candidates on a grid over the room; then farthest-point sampling, the first one farthest from
  // the room's centroid: pins far apart align the stack best.
  ClipperLib::cInt x0 = std::numeric_limits<ClipperLib::cInt>::max(), y0 = x0, x1 = -x0, y1 = -x0;
  for (const auto& ring : room)
    for (const auto& p : ring) x0 = std::min(x0, p.X), x1 = std::max(x1, p.X), y0 = std::min(y0, p.Y), y1 = std::max(y1, p.Y);
  const double w = (x1 - x0) / geometry_detail::kClipperUnitsPerMm, h = (y1 - y0) / geometry_detail::kClipperUnitsPerMm;
  const double step = std::max({w, h, 1e-3}) / 120.0;
  std::vector<Eigen::Vector2d> candidates;
  Eigen::Vector2d centroid = Eigen::Vector2d::Zero();
  for (double y = y0 / geometry_detail::kClipperUnitsPerMm + 0.5 * step; y < y1 / geometry_detail::kClipperUnitsPerMm; y += step)
    for (double x = x0 / geometry_detail::kClipperUnitsPerMm + 0.5 * step; x < x1 / geometry_detail::kClipperUnitsPerMm; x += step) {
      const Eigen::Vector2d p(x, y);
      if (inside(room, p)) candidates.push_back(p), centroid += p;
    }
  // A room thinner than the grid: its own vertices are candidates too.
  for (const auto& ring : room)
    for (const auto& p : ring) {
      const Eigen::Vector2d q(p.X / geometry_detail::kClipperUnitsPerMm, p.Y / geometry_detail::kClipperUnitsPerMm);
      candidates.push_back(q), centroid += q;
    }
  centroid /= static_cast<double>(candidates.size());

  std::vector<Eigen::Vector2d> chosen;
  std::vector<double> nearest(candidates.size(), std::numeric_limits<double>::infinity());
  for (std::size_t i = 0; i < candidates.size(); ++i) nearest[i] = (candidates[i] - centroid).norm();
  const double min_apart = params.diameter_mm + params.wall_mm;
  while (static_cast<int>(chosen.size()) < params.count) {
    const auto best = std::max_element(nearest.begin(), nearest.end());
    if (*best < min_apart && !chosen.empty()) break;
    const Eigen::Vector2d p = candidates[static_cast<std::size_t>(best - nearest.begin())];
    chosen.push_back(p);
    for (std::size_t i = 0; i < candidates.size(); ++i)
      nearest[i] = chosen.size() == 1 ? (candidates[i] - p).norm() : std::min(nearest[i], (candidates[i] - p).norm());
  }
  if (static_cast<int>(chosen.size()) < params.count)
    return std::unexpected(invalid_argument(fmt::format(
        "dowels: only {} of {} dowels of {} mm fit {} mm apart where every layer has material", chosen.size(),
        params.count, params.diameter_mm, min_apart)));
  return chosen;
}

namespace {

// One part: the outer outline oi of a layer with its holes.
std::expected<Part, Error> make_part(const LayerPlan& layer, std::size_t slot, std::size_t oi, int island,
                                     const PartParams& params, const std::vector<Eigen::Vector2d>& dowels) {
  const LayerOutline& outer = layer.outlines[oi];
  for (const CutPass& pass : outer.passes)
    if (pass.lines.size() < 3)
      return std::unexpected(invalid_argument(fmt::format("layer {} outline {}: a pass with {} cut lines (needs 3 or more)",
                                                          layer.index, oi, pass.lines.size())));
  if (outer.passes.empty())
    return std::unexpected(invalid_argument(fmt::format("layer {} outline {}: no cut passes", layer.index, oi)));
  Part part;
  part.layer_slot = static_cast<int>(slot);
  part.layer = layer.index;
  part.island = island;
  part.outer = static_cast<int>(oi);
  part.thickness_mm = layer.thickness_mm;
  part.z_bottom_mm = layer.z_bottom_mm;
  for (std::size_t hi = 0; hi < layer.outlines.size(); ++hi)
    if (layer.outlines[hi].is_hole && layer.outlines[hi].parent == static_cast<int>(oi))
      part.holes.push_back(static_cast<int>(hi));

  // Footprint: everything any pass reaches on either face, plus half the kerf.
  const ClipperLib::Paths reach = offset(boolean(ClipperLib::ctUnion, pass_rings(outer), {}), 0.5 * params.kerf_mm);
  const ClipperLib::Path* largest = nullptr;
  for (const auto& ring : reach)
    if (ClipperLib::Orientation(ring) && (!largest || ClipperLib::Area(ring) > ClipperLib::Area(*largest))) largest = &ring;
  if (!largest)
    return std::unexpected(invalid_argument(fmt::format("layer {} outline {}: the cuts enclose no area", layer.index, oi)));
  part.footprint_mm = geometry_detail::from_clipper(*largest);

  // Free room in each hole: inside every ring of the hole on both faces, less half the kerf.
  for (const int hi : part.holes) {
    ClipperLib::Paths room;
    bool first = true;
    for (ClipperLib::Path& ring : pass_rings(layer.outlines[static_cast<std::size_t>(hi)])) {
      if (ClipperLib::Area(ring) < 0) ClipperLib::ReversePath(ring);
      room = first ? ClipperLib::Paths{ring} : boolean(ClipperLib::ctIntersection, room, {ring});
      first = false;
    }
    for (const auto& ring : offset(room, -0.5 * params.kerf_mm))
      if (ClipperLib::Orientation(ring) && ClipperLib::Area(ring) > 0) part.free_holes_mm.push_back(geometry_detail::from_clipper(ring));
  }

  // Material at each face of the freeing pass, holes removed; the larger face counts.
  auto face_area = [&](bool top) {
    auto ring_area = [&](const LayerOutline& o) {
      Polygon2 r;
      for (const CutLine& l : o.passes.back().lines) r.emplace_back(top ? l.top_mm.head<2>() : l.bottom_mm.head<2>());
      return std::abs(signed_area_mm2(r));
    };
    double a = ring_area(outer);
    for (int hi : part.holes) a -= ring_area(layer.outlines[static_cast<std::size_t>(hi)]);
    return a;
  };
  part.area_mm2 = std::max(face_area(true), face_area(false));

  // The dowels that land in this part: inside its freeing pass on both faces.
  LayerPlan alone;
  alone.outlines = {outer};
  const ClipperLib::Paths material = certain_material(alone);
  for (const Eigen::Vector2d& d : dowels)
    if (inside(material, d)) part.dowels_mm.push_back(d);
  return part;
}

}  // namespace

// Layer by layer on the pool (the 1M sphere's 23 layers took 0.25 s one after the other), taken
// in layer order: the parts in that order, the first failing layer's error.
std::expected<std::vector<Part>, Error> make_parts(const BevelPlan& plan, const PartParams& params) {
  if (!std::isfinite(params.kerf_mm) || params.kerf_mm < 0.0)
    return std::unexpected(invalid_argument(fmt::format("kerf {} mm must be finite and >= 0", params.kerf_mm)));
  auto dowels = place_dowels(plan, params.dowels);
  if (!dowels) return std::unexpected(dowels.error());

  std::vector<std::expected<std::vector<Part>, Error>> per_layer(plan.layers.size());
  tbb::parallel_for(std::size_t{0}, plan.layers.size(), [&](std::size_t slot) {
    const LayerPlan& layer = plan.layers[slot];
    std::vector<Part> parts;
    int island = 0;
    for (std::size_t oi = 0; oi < layer.outlines.size(); ++oi) {
      if (layer.outlines[oi].is_hole) continue;
      auto part = make_part(layer, slot, oi, ++island, params, *dowels);
      if (!part) {
        per_layer[slot] = std::unexpected(part.error());
        return;
      }
      parts.push_back(std::move(*part));
    }
    per_layer[slot] = std::move(parts);
  });
  std::vector<Part> parts;
  for (auto& layer : per_layer) {
    if (!layer) return std::unexpected(layer.error());
    for (Part& p : *layer) parts.push_back(std::move(p));
  }
  return parts;
}

}  // namespace lamina
