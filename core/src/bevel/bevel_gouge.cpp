// Keeping outside cuts off the model's material between stations (bevel_gouge.hpp).
#include "bevel/bevel_gouge.hpp"

#include "geometry/clipper_bridge.hpp"
#include "geometry/stack_geometry.hpp"
#include "lamina/core/box_grid.hpp"

#include <polyclipping/clipper.hpp>

#include <algorithm>
#include <cmath>
#include <limits>

namespace lamina::bevel_detail {
using geometry_detail::edge_ring;
using geometry_detail::from_clipper;
using geometry_detail::kClipperUnitsPerMm;
using geometry_detail::layer_t;
using geometry_detail::outline_usable;
using geometry_detail::to_clipper;
namespace {

// Moving a station changes its neighbours' chords too: a few rounds settle every corner.
constexpr int kRounds = 6;
// A chord that faces away from both its stations' normals moves slowly when they move; below
// this the shift is computed as if it moved at this rate (and the next round checks again).
constexpr double kMinChordRate = 0.25;
// Pieces of material outside the cuts with less area than this are rounding slivers.
constexpr double kMinPieceArea = 1e-8;

struct Chord {
  int outline;
  std::size_t a, b;  // stations
  Eigen::Vector2d pa, pb;
  Eigen::Vector2d lo, hi;  // bounding box
};

std::vector<Chord> chords_at(const LayerPlan& layer, double z) {
  std::vector<Chord> out;
  const double t = layer_t(layer, z);
  for (std::size_t o = 0; o < layer.outlines.size(); ++o) {
    const LayerOutline& outline = layer.outlines[o];
    if (!outline_usable(outline)) continue;
    const Polygon2 ring = edge_ring(outline, t);
    for (std::size_t a = 0; a < ring.size(); ++a) {
      const std::size_t b = (a + 1) % ring.size();
      if ((ring[b] - ring[a]).norm() < 1e-9) continue;
      out.push_back({static_cast<int>(o), a, b, ring[a], ring[b], ring[a].cwiseMin(ring[b]), ring[a].cwiseMax(ring[b])});
    }
  }
  return out;
}

double distance_to(const Eigen::Vector2d& q, const Chord& c) {
  const Eigen::Vector2d d = c.pb - c.pa;
  const double s = std::clamp((q - c.pa).dot(d) / d.squaredNorm(), 0.0, 1.0);
  return (c.pa + s * d - q).norm();
}

// The chords of one height bucketed on a grid, so that a point's nearest chord is found among
// the cells around it (a ring of cells at a time, until no unvisited cell can hold a nearer one)
// instead of among every chord of the layer: the sphere's outlines have thousands of chords, and
// every vertex of every sliver of material outside them asks.
class ChordIndex {
 public:
  explicit ChordIndex(std::vector<Chord> chords) : chords_(std::move(chords)) {
    std::vector<Box2> boxes;
    boxes.reserve(chords_.size());
    for (const Chord& c : chords_) boxes.push_back({c.lo, c.hi});
    grid_ = BoxGrid(boxes, [](const Eigen::Vector2d& size, std::size_t count) {
      return std::max(std::sqrt(size.x() * size.y() / static_cast<double>(count)), std::max(size.x(), size.y()) / 1024.0);
    });
  }

  // The nearest chord and its distance; of equal distances the first in chord order, as a scan
  // of every chord would give.
  const Chord* nearest(const Eigen::Vector2d& q, double& best) const {
    best = std::numeric_limits<double>::infinity();
    if (grid_.empty()) return nullptr;
    std::size_t best_index = chords_.size();
    const int cx = grid_.column(q.x()), cy = grid_.row(q.y());
    const double cell = grid_.cell_mm();
    const int rings = std::max({cx, cy, grid_.nx() - 1 - cx, grid_.ny() - 1 - cy});
    for (int r = 0; r <= rings; ++r) {
      for (int y = cy - r; y <= cy + r; ++y) {
        if (y < 0 || y >= grid_.ny()) continue;
        const bool edge_row = y == cy - r || y == cy + r;
        for (int x = cx - r; x <= cx + r; x += (edge_row ? 1 : 2 * r)) {
          if (x >= 0 && x < grid_.nx()) visit(grid_.cell(x, y), q, best, best_index);
          if (r == 0) break;
        }
      }
      // Every cell not visited lies outside the block of cells cx±r, cy±r.
      const Eigen::Vector2d block_lo = grid_.origin() + cell * Eigen::Vector2d(cx - r, cy - r);
      const Eigen::Vector2d block_hi = grid_.origin() + cell * Eigen::Vector2d(cx + r + 1, cy + r + 1);
      const double margin = std::min({q.x() - block_lo.x(), block_hi.x() - q.x(), q.y() - block_lo.y(), block_hi.y() - q.y()});
      if (margin > best) break;
    }
    return best_index < chords_.size() ? &chords_[best_index] : nullptr;
  }

 private:
  void visit(std::size_t cell, const Eigen::Vector2d& q, double& best, std::size_t& best_index) const {
    for (const std::uint32_t i : grid_.items(cell)) {
      const Chord& c = chords_[i];
      const Eigen::Vector2d gap = (c.lo - q).cwiseMax(q - c.hi).cwiseMax(0.0);
      if (gap.norm() > best) continue;
      const double d = distance_to(q, c);
      if (d < best || (d == best && i < best_index)) {
        best = d;
        best_index = i;
      }
    }
  }

  std::vector<Chord> chords_;
  BoxGrid grid_;
};

// Finds material of the sub-slices outside the layer's section; for each piece's vertices the
// chord they lie beyond and how far each of its stations must move out. Returns the deepest.
struct Gouges {
  double worst = 0.0;
  double worst_marked = 0.0;  // on chords `marked` says
};

Gouges find_gouges(const LayerPlan& layer, const std::vector<const Slice*>& sub_slices,
                   const std::vector<ClipperLib::Paths>& material, std::vector<std::vector<double>>* shift,
                   const std::vector<std::vector<char>>* marked = nullptr) {
  Gouges worst;
  for (std::size_t j = 0; j < sub_slices.size(); ++j) {
    const double z = sub_slices[j]->z_mm;
    ClipperLib::Clipper c;
    c.AddPaths(material[j], ClipperLib::ptSubject, true);
    c.AddPaths(to_clipper(layer_section(layer, z)), ClipperLib::ptClip, true);
    ClipperLib::Paths outside;
    c.Execute(ClipperLib::ctDifference, outside, ClipperLib::pftPositive, ClipperLib::pftPositive);
    if (outside.empty()) continue;
    const ChordIndex chords(chords_at(layer, z));
    for (const ClipperLib::Path& piece : outside) {
      if (std::abs(ClipperLib::Area(piece)) < kMinPieceArea * kClipperUnitsPerMm * kClipperUnitsPerMm) continue;
      for (const Eigen::Vector2d& q : from_clipper(piece)) {
        double d = 0.0;
        const Chord* ch = chords.nearest(q, d);
        if (!ch || d <= kGougeTolerance) continue;
        // Material lies on the left of every ring's direction: the scrap side is the right.
        const Eigen::Vector2d dir = (ch->pb - ch->pa).normalized();
        const Eigen::Vector2d scrap(dir.y(), -dir.x());
        const double depth = (q - ch->pa).dot(scrap);
        if (depth <= kGougeTolerance) continue;  // not beyond this chord: nothing a move here mends
        worst.worst = std::max(worst.worst, depth);
        if (marked) {
          const auto& m = (*marked)[static_cast<std::size_t>(ch->outline)];
          if (ch->a < m.size() && m[ch->a]) worst.worst_marked = std::max(worst.worst_marked, depth);
        }
        if (!shift) continue;
        const LayerOutline& outline = layer.outlines[static_cast<std::size_t>(ch->outline)];
        const double rate = std::max(kMinChordRate, std::min(outline.stations[ch->a].normal.dot(scrap),
                                                             outline.stations[ch->b].normal.dot(scrap)));
        const double need = depth / rate + kGougeTolerance;
        auto& s = (*shift)[static_cast<std::size_t>(ch->outline)];
        s[ch->a] = std::max(s[ch->a], need);
        s[ch->b] = std::max(s[ch->b], need);
      }
    }
  }
  return worst;
}

void move_station(LayerOutline& outline, std::size_t s, double by_mm) {
  const Eigen::Vector2d n = outline.stations[s].normal;
  for (CutPass& pass : outline.passes) {
    CutLine& l = pass.lines[s];
    l.top_mm.head<2>() += by_mm * n;
    l.bottom_mm.head<2>() += by_mm * n;
  }
  outline.stations[s].max_deviation_mm += by_mm;
  outline.max_deviation_mm = std::max(outline.max_deviation_mm, outline.stations[s].max_deviation_mm);
}

// How deep q lies inside the material (0 outside). Whether it is inside at all comes from the
// sub-slice's section lines (a grid: a moved station asks at every sub-slice and pass, and a
// point-in-polygon test of every ring was 20 M corner visits per layer of the 1M sphere once its
// stations were no longer the mesh's corners); only a point inside is measured.
double depth_inside(const Eigen::Vector2d& q, const SectionLines& lines, const ClipperLib::Paths& material) {
  if (!lines.contains(q)) return 0.0;
  double nearest = std::numeric_limits<double>::infinity();
  for (const ClipperLib::Path& path : material) {
    const std::vector<Eigen::Vector2d> ring = from_clipper(path);
    for (std::size_t i = 0; i < ring.size(); ++i) {
      const Chord edge{0, 0, 0, ring[i], ring[(i + 1) % ring.size()], {}, {}};
      if ((edge.pb - edge.pa).squaredNorm() > 0) nearest = std::min(nearest, distance_to(q, edge));
    }
  }
  return nearest;
}

// A station moved out of one corner's material must not have moved into other material (a
// strand of a knot beside it, another outline of the section): its lines are checked at every
// sub-slice; a move that enters material is undone, and the gouge it was for stays reported.
bool enters_material(const LayerOutline& outline, std::size_t s, const std::vector<const Slice*>& sub_slices,
                     const std::vector<SectionLines>& lines, const std::vector<ClipperLib::Paths>& material) {
  for (const CutPass& pass : outline.passes) {
    const CutLine& l = pass.lines[s];
    const double dz = l.top_mm.z() - l.bottom_mm.z();
    for (std::size_t j = 0; j < sub_slices.size(); ++j) {
      const double f = std::abs(dz) > 1e-12 ? (sub_slices[j]->z_mm - l.bottom_mm.z()) / dz : 0.0;
      const Eigen::Vector2d q = (l.bottom_mm + std::clamp(f, 0.0, 1.0) * (l.top_mm - l.bottom_mm)).head<2>();
      if (depth_inside(q, lines[j], material[j]) > kGougeTolerance) return true;
    }
  }
  return false;
}

}  // namespace

GougeClearance clear_gouges(LayerPlan& layer, const std::vector<const Slice*>& sub_slices,
                            const std::vector<SectionLines>& lines, double max_shift_mm,
                            const std::vector<std::vector<char>>* marked) {
  GougeClearance r;
  std::vector<ClipperLib::Paths> material;
  material.reserve(sub_slices.size());
  for (const Slice* s : sub_slices) material.push_back(geometry_detail::slice_material(*s));

  std::vector<std::vector<double>> moved(layer.outlines.size()), shift(layer.outlines.size());
  for (std::size_t o = 0; o < layer.outlines.size(); ++o) moved[o].assign(layer.outlines[o].stations.size(), 0.0);
  for (int round = 0; round < kRounds; ++round) {
    for (std::size_t o = 0; o < layer.outlines.size(); ++o) shift[o].assign(layer.outlines[o].stations.size(), 0.0);
    const Gouges found = find_gouges(layer, sub_slices, material, &shift, round == 0 ? marked : nullptr);
    if (round == 0) {
      r.worst_found_mm = found.worst;
      r.worst_found_loose_mm = found.worst_marked;
    }
    bool any = false;
    for (std::size_t o = 0; o < layer.outlines.size(); ++o) {
      for (std::size_t s = 0; s < shift[o].size(); ++s) {
        const double by = std::min(shift[o][s], max_shift_mm - moved[o][s]);
        if (!(by > 0.0)) continue;
        if (moved[o][s] == 0.0) ++r.stations_moved;
        moved[o][s] += by;
        r.largest_shift_mm = std::max(r.largest_shift_mm, moved[o][s]);
        move_station(layer.outlines[o], s, by);
        any = true;
      }
    }
    if (!any) break;
  }
  for (std::size_t o = 0; o < layer.outlines.size(); ++o) {
    for (std::size_t s = 0; s < moved[o].size(); ++s) {
      if (moved[o][s] > 0.0 && enters_material(layer.outlines[o], s, sub_slices, lines, material)) {
        move_station(layer.outlines[o], s, -moved[o][s]);
        ++r.moves_undone;
      }
    }
  }
  r.worst_left_mm = r.stations_moved > 0 ? find_gouges(layer, sub_slices, material, nullptr).worst : r.worst_found_mm;
  for (const LayerOutline& outline : layer.outlines)
    layer.max_deviation_mm = std::max(layer.max_deviation_mm, outline.max_deviation_mm);
  return r;
}

}  // namespace lamina::bevel_detail
