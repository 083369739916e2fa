// True-shape nesting with libnest2d 5.0.0 (Ultimaker's fork, as Cura's arrange uses it): the
// no-fit-polygon placer with first-fit selection, Clipper backend, NLopt subplex optimiser.
//
// libnest2d's Clipper backend computes no-fit polygons for convex shapes only
// (nfp::MaxNfpLevel = CONVEX_ONLY; a concave shape given to nfpConvexOnly yields a wrong NFP and
// overlaps). So each part goes in as the convex hull of its footprint — what Cura does with its
// models' hulls — inflated by half the spacing; parts never interlock concavities or sit in holes.
#include "geometry/clipper_bridge.hpp"
#include "cam/nest_fit.hpp"
#include "cam/nest_internal.hpp"

// libnest2d runs on TBB's pool (LIBNEST2D_THREADING_tbb, core/CMakeLists.txt): its std threading
// started a thread (std::async) per no-fit polygon and per optimiser start point, some 10^5
// threads for a hundred parts, a third of the packing time spent in the kernel making and
// unmapping them. The tasks are independent and the best is still the first best by index, so
// the nest does not change.

#include <libnest2d/common.hpp>

// libnest2d 5.0.0 is C++11: under C++20's rewritten comparisons `Radians != Radians` is ambiguous
// (built-in double via two conversions, and operator==(Degrees, Radians) reversed). Exact matches
// declared before the rest of the library resolve it.
namespace libnest2d {
inline bool operator==(const Radians& a, const Radians& b) { return static_cast<double>(a) == static_cast<double>(b); }
inline bool operator!=(const Radians& a, const Radians& b) { return !(a == b); }
}  // namespace libnest2d

#include <libnest2d/libnest2d.hpp>

#include <algorithm>
#include <numbers>
#include <limits>
#include <Eigen/Core>
#include <cmath>

namespace lamina::cam_detail {
using geometry_detail::kClipperUnitsPerMm;
using geometry_detail::to_clipper;

namespace {

namespace ln = libnest2d;

// The half-spacing offset uses mitred joins (squared beyond Clipper's miter limit 2): every point
// of the grown ring is at least the offset from the hull (round joins cut corners with chords);
// kSlackMm (nest_internal.hpp) more than half the spacing.

using Path = ClipperLib::Path;
using IntPoint = ClipperLib::IntPoint;

// Hulls with more corners than this are replaced by a circumscribed polygon: libnest2d's no-fit
// polygons cost grows with the product of both shapes' corners, and a sliced sphere's 1000-corner
// rings made 23 parts take 15 s. 64 supporting lines stand at most R·(1/cos(π/64) − 1) = 0.12 % of
// the radius off a round part: 0.06 mm on Ø100.
constexpr std::size_t kMaxHullCorners = 64;

// The shape libnest2d places for a part: hull offset by `delta_mm` (mitred), clockwise and
// closed as libnest2d's Clipper backend expects.
ClipperLib::Polygon item_shape(const Part& part, double delta_mm) {
  Path hull = convex_hull(to_clipper(part.footprint_mm));
  if (hull.size() > kMaxHullCorners) hull = circumscribed(hull, static_cast<int>(kMaxHullCorners));
  ClipperLib::Paths grown;
  ClipperLib::ClipperOffset off;
  off.AddPath(hull, ClipperLib::jtMiter, ClipperLib::etClosedPolygon);
  off.Execute(grown, delta_mm * kClipperUnitsPerMm);
  ClipperLib::Polygon shape;
  // A convex ring grown stays one convex ring.
  for (auto& r : grown)
    if (ClipperLib::Orientation(r) && r.size() > shape.Contour.size()) shape.Contour = r;
  ClipperLib::ReversePath(shape.Contour);
  if (!shape.Contour.empty()) shape.Contour.push_back(shape.Contour.front());
  return shape;
}

// The items, each at the first listed rotation at which it fits the bin: libnest2d puts the
// first item of a bin at its current rotation.
std::vector<ln::Item> shape_items(std::span<const Part> parts, std::span<const int> which, double delta,
                                  const ln::Box& bin, const std::vector<double>& rotations) {
  std::vector<ln::Item> items;
  items.reserve(which.size());
  for (int p : which) {
    items.emplace_back(item_shape(parts[p], delta));
    double start = rotations.front();
    for (double a : rotations) {
      ln::Item probe = items.back();
      probe.rotation(a);
      const auto bb = probe.boundingBox();
      if (bb.width() <= bin.width() && bb.height() <= bin.height()) {
        start = a;
        break;
      }
    }
    items.back().rotation(start);
  }
  return items;
}

// The pile placed so far, as the placer's callbacks see it.
struct Pile {
  ln::Box box;
  bool any = false;
};

// Fill the sheet from one end: keep the pile short along x (the sheet's length), then low and to
// the left. libnest2d checks that the pile's bounding box fits the bin and moves the pile into
// the bin's bottom-left corner at the end.
void configure_placer(ln::NestConfig<ln::NfpPlacer, ln::FirstFitSelection>& cfg, const NestParams& params,
                      const ln::Box& bin, Pile& pile) {
  auto& pc = cfg.placer_config;
  const double base = params.rotations_rad.front();
  pc.rotations.clear();
  for (double a : params.rotations_rad) pc.rotations.emplace_back(a - base);
  pc.alignment = ln::NfpPlacer::Config::Alignment::BOTTOM_LEFT;
  pc.starting_point = ln::NfpPlacer::Config::Alignment::BOTTOM_LEFT;
  pc.parallel = params.parallel;
  pc.accuracy = 0.65f;
  const double len = static_cast<double>(bin.width());
  const double wid = static_cast<double>(bin.height());
  pc.before_packing = [&pile](const ln::nfp::Shapes<ClipperLib::Polygon>& merged,
                              const ln::_ItemGroup<ClipperLib::Polygon>&, const ln::_ItemGroup<ClipperLib::Polygon>&) {
    pile.any = !merged.empty();
    if (pile.any) pile.box = ln::shapelike::boundingBox(merged);
  };
  pc.object_function = [&pile, len, wid](const ln::Item& item) {
    const ln::Box ib = item.boundingBox();
    const ln::Box full = pile.any ? ln::shapelike::boundingBox(pile.box, ib) : ib;
    // Positions whose pile would not fit the bin score worse than any that fits (libnest2d keeps
    // only the best local optimum of a no-fit polygon and drops it if it does not fit).
    const double over = std::max(0.0, static_cast<double>(full.width()) - len) / len +
                        std::max(0.0, static_cast<double>(full.height()) - wid) / wid;
    const double x_extent = static_cast<double>(full.width()) / len;
    const double y_low = static_cast<double>(ib.maxCorner().Y - full.minCorner().Y) / wid;
    const double x_low = static_cast<double>(ib.maxCorner().X - full.minCorner().X) / len;
    return x_extent + 0.1 * y_low + 0.01 * x_low + (over > 0.0 ? 10.0 + over : 0.0);
  };
}

// How far libnest2d's placed shape is from our placement of the raw one, at worst (mm).
double transform_error_mm(const ln::Item& it, const Placement& pl) {
  double worst = 0.0;
  const auto& raw = it.rawShape().Contour;
  const auto& placed = it.transformedShape().Contour;
  for (std::size_t v = 0; v < raw.size() && v < placed.size(); ++v) {
    const Eigen::Vector2d layer(static_cast<double>(raw[v].X) / kClipperUnitsPerMm,
                                static_cast<double>(raw[v].Y) / kClipperUnitsPerMm);
    const Eigen::Vector2d want(static_cast<double>(placed[v].X) / kClipperUnitsPerMm,
                               static_cast<double>(placed[v].Y) / kClipperUnitsPerMm);
    worst = std::max(worst, (place_point(pl, layer) - want).norm());
  }
  return worst;
}

}  // namespace

std::vector<PackedSheet> pack_shape(std::span<const Part> parts, std::span<const int> which, SheetSize size,
                                    const NestParams& params, std::vector<int>& unplaced,
                                    ShapePackDiagnostics* diagnostics) {
  const double delta = 0.5 * params.spacing_mm + kSlackMm;
  // The bin: sheet minus margin, grown by half the spacing (the items are grown by about as much).
  const double grow = params.margin_mm - 0.5 * params.spacing_mm;
  auto nm = [](double mm) { return static_cast<ClipperLib::cInt>(std::llround(mm * kClipperUnitsPerMm)); };
  const ln::Box bin({nm(grow), nm(grow)}, {nm(size.length_mm - grow), nm(size.width_mm - grow)});
  std::vector<ln::Item> items = shape_items(parts, which, delta, bin, params.rotations_rad);
  ln::NestConfig<ln::NfpPlacer, ln::FirstFitSelection> cfg;
  Pile pile;
  configure_placer(cfg, params, bin, pile);
  // libnest2d says how many items remain after each one it packs.
  ln::nest(items, bin, 0, cfg, ln::NestControl([&params](unsigned) {
             if (params.on_placed) params.on_placed();
           }));

  int bins = 0;
  for (const auto& it : items) bins = std::max(bins, it.binId() + 1);
  std::vector<PackedSheet> out(static_cast<std::size_t>(bins));
  // Placements on a sheet in the order of `which` (libnest2d sorts its own copy by area).
  double worst = 0.0;
  for (std::size_t i = 0; i < items.size(); ++i) {
    const ln::Item& it = items[i];
    const int part = which[i];
    if (it.binId() < 0) {
      unplaced.push_back(part);
      continue;
    }
    Placement pl;
    pl.part = part;
    pl.rotation_rad = static_cast<double>(it.rotation());
    pl.offset_mm = Eigen::Vector2d(static_cast<double>(it.translation().X), static_cast<double>(it.translation().Y)) /
                   kClipperUnitsPerMm;
    out[static_cast<std::size_t>(it.binId())].placements.push_back(pl);
    if (diagnostics) {  // the same map applied to the raw (untransformed) item must give libnest2d's shape
      worst = std::max(worst, transform_error_mm(it, pl));
      ++diagnostics->items;
    }
  }
  if (diagnostics) diagnostics->max_transform_error_mm = std::max(diagnostics->max_transform_error_mm, worst);
  return out;
}

}  // namespace lamina::cam_detail
