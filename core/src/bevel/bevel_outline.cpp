// The layer outline a bevel plan's stations go on (bevel_outline.hpp): the union of the
// sub-slices and the shadows between them, simplified off the material where its corners are
// finer than the stations need, and the stations along it.
#include "bevel/bevel_outline.hpp"

#include "geometry/ring_simplify.hpp"

#include <algorithm>
#include <cmath>

namespace lamina::bevel_detail {

namespace {

// A ring of the outline with fewer corners, `by_mm` off the material (outer rings grow, holes
// shrink), or the ring itself: a finely tessellated model (the 1M sphere, 1000 corners per
// ring) would otherwise get a station at every corner, 0.3 mm apart, while the profile between
// stations spaced by station_spacing_mm is what the cut follows. Off the material, every
// sub-slice's crossing lies inside the outline, where a station's line looks for it.
//
// Corners that turn by more than kKeepTurnRad stay stations: where a sub-slice's sharp corner
// stands a little off its neighbours' (a twisted prism's tips, 0.37 mm apart and 2 µm off the
// chord between the outer two), the chord between the stations either side cut the middle tip
// and the gouge clearing moved them out 0.28 mm.
constexpr double kKeepTurnRad = 15.0 * M_PI / 180.0;

// A ring that would keep more than kWorthSimplifying of its corners is kept whole: it saves
// little planning for a plan that differs (openscad_example006's rings lost 0.2 % of their
// corners).
constexpr double kWorthSimplifying = 0.75;

geometry_detail::SimplifiedRing simplified_off_material(const ClipperLib::Path& path, double by_mm) {
  const geometry_detail::SimplifiedRing whole{path, {}};
  if (!(by_mm > 0.0)) return whole;
  geometry_detail::SimplifiedRing out;
  if (ClipperLib::Orientation(path)) {
    out = geometry_detail::simplified_beside_marked(path, by_mm, kKeepTurnRad);
  } else {  // material outside it: the hole itself, inwards, and back in the hole's direction
    const ClipperLib::Path hole(path.rbegin(), path.rend());
    const geometry_detail::SimplifiedRing in = geometry_detail::simplified_beside_marked(hole, -by_mm, kKeepTurnRad);
    const std::size_t m = in.ring.size();
    out.ring.assign(in.ring.rbegin(), in.ring.rend());
    out.chord.resize(m);
    for (std::size_t j = 0; j < m; ++j) out.chord[j] = in.chord[(2 * m - 2 - j) % m];  // edge j is in's m-2-j reversed
  }
  if (static_cast<double>(out.ring.size()) > kWorthSimplifying * static_cast<double>(path.size())) return whole;
  return out;
}

bool sharp_corner(const Polygon2& ring, std::size_t i) {
  const std::size_t n = ring.size();
  const Eigen::Vector2d a = ring[i] - ring[(i + n - 1) % n], b = ring[(i + 1) % n] - ring[i];
  return std::abs(std::atan2(a.x() * b.y() - a.y() * b.x(), a.dot(b))) > kKeepTurnRad;
}

}  // namespace

std::vector<OutlineRing> layer_outline_rings(const std::vector<const Slice*>& sub_slices, ClipperLib::Paths all,
                                             double min_hole_width_mm, double simplify_mm, bool& simplified) {
  for (const Slice* s : sub_slices) {
    for (const Loop& l : s->loops) all.push_back(geometry_detail::to_clipper(l.points));
  }
  ClipperLib::Clipper clipper;
  clipper.AddPaths(all, ClipperLib::ptSubject, true);
  ClipperLib::PolyTree tree;
  clipper.Execute(ClipperLib::ctUnion, tree, ClipperLib::pftPositive, ClipperLib::pftPositive);
  std::vector<OutlineRing> rings;
  // Drop vertices closer than 0.1 µm and collinear runs: unions of near-identical sub-slices
  // leave such crumbs, and every vertex becomes a station.
  auto add = [&](const ClipperLib::PolyNode& node, int parent) {
    ClipperLib::Path path = node.Contour;
    ClipperLib::CleanPolygon(path, 100.0);
    if (path.size() < 3) return -1;
    geometry_detail::SimplifiedRing fewer = simplified_off_material(path, simplify_mm);
    simplified = simplified || fewer.ring.size() != path.size();
    OutlineRing r;
    r.points = geometry_detail::from_clipper(fewer.ring);
    if (fewer.ring.size() != path.size()) r.chord = std::move(fewer.chord);
    r.is_hole = node.IsHole();
    r.parent = parent;
    const double area = std::abs(signed_area_mm2(r.points));
    if (area < 1e-8) return -1;
    if (r.is_hole) {
      // Mean width of the hole (2·area / perimeter): slivers between sub-slices that no jet can
      // cut are left closed — keeping material there is on the safe side of "outside".
      double perimeter = 0.0;
      for (std::size_t i = 0; i < r.points.size(); ++i) perimeter += (r.points[(i + 1) % r.points.size()] - r.points[i]).norm();
      if (2.0 * area / perimeter < min_hole_width_mm) return -2;
    }
    rings.push_back(std::move(r));
    return static_cast<int>(rings.size()) - 1;
  };
  std::vector<std::pair<const ClipperLib::PolyNode*, int>> stack;
  for (const ClipperLib::PolyNode* child : tree.Childs) stack.emplace_back(child, -1);
  while (!stack.empty()) {
    auto [node, parent] = stack.back();
    stack.pop_back();
    const int self = add(*node, node->IsHole() ? parent : -1);
    if (self == -2) continue;  // a closed sliver: what lies inside it is inside the material
    // Holes belong to the outer above them; islands inside a hole are new outers.
    for (const ClipperLib::PolyNode* child : node->Childs) stack.emplace_back(child, node->IsHole() ? -1 : self);
  }
  return rings;
}

// Normals point out of the material for outer and hole rings alike (material is on the left of
// the ring's direction).
std::vector<StationSeed> station_seeds(const OutlineRing& outline, double spacing_mm) {
  const Polygon2& ring = outline.points;
  const std::size_t n = ring.size();
  std::vector<Eigen::Vector2d> edge_normal(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector2d e = ring[(i + 1) % n] - ring[i];
    const double len = e.norm();
    edge_normal[i] = len > 0 ? Eigen::Vector2d(e.y() / len, -e.x() / len) : Eigen::Vector2d::Zero();
  }
  std::vector<StationSeed> seeds;
  seeds.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    Eigen::Vector2d nrm = edge_normal[(i + n - 1) % n] + edge_normal[i];
    nrm = nrm.norm() > 1e-12 ? nrm.normalized() : edge_normal[i];
    const Eigen::Vector2d a = ring[i], b = ring[(i + 1) % n];
    const double len = (b - a).norm();
    const int extra = spacing_mm > 0 ? static_cast<int>(std::ceil(len / spacing_mm)) - 1 : 0;
    const bool chord = !outline.chord.empty() && outline.chord[i];
    const bool ends_sharp = chord && sharp_corner(ring, (i + 1) % n);
    seeds.push_back({ring[i], nrm, chord && !sharp_corner(ring, i) && (extra > 0 || !ends_sharp)});
    for (int k = 1; k <= extra; ++k) {
      const double t = static_cast<double>(k) / (extra + 1);
      seeds.push_back({a + t * (b - a), edge_normal[i], chord && (k < extra || !ends_sharp)});
    }
  }
  return seeds;
}

// The outline as a section, to find how far out a line may go before it meets other material
// of the same layer.
Slice outline_section(const std::vector<OutlineRing>& rings) {
  Slice outline_slice;
  for (const OutlineRing& ring : rings) {
    Loop loop;
    loop.points = ring.points;
    loop.facets.assign(ring.points.size(), -1);
    loop.area_mm2 = signed_area_mm2(ring.points);
    outline_slice.loops.push_back(std::move(loop));
  }
  return outline_slice;
}

}  // namespace lamina::bevel_detail
