// Hole filling: smaller parts inside the free holes of larger ones, before packing (both methods).
//
// A child's footprint must stay `spacing` from the hole's free ring (the room no cut of the hole
// reaches, already less half the kerf: the child's own outer lead-ins need that gap, as between
// any two parts) and `spacing` from the other children of that hole. So its footprint must lie
// in the room  R = (hole eroded by spacing) minus (each child there grown by spacing),  and the
// translations t that put a candidate C there are  inner_fit(hole eroded, C) minus, per child G,
// the no-fit region G ⊕ (−C)  (nest_fit.hpp). Both sides are simplified conservatively first (the
// hole inwards, C and the children outwards, erosion and growth mitred) and 10 nm are added to
// the spacing for the rounding to nm; the position chosen is then checked on the real footprints.
//
// Nesting is recursive: hosts go by decreasing footprint area, and a part fits only a hole
// smaller than its host, so a part put in a hole has no children yet; it may get its own when its
// turn as a host comes (a stack of rings nests like Russian dolls).
#include "cam/nest_fit.hpp"
#include "cam/nest_internal.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>

namespace lamina::cam_detail {
using geometry_detail::area_mm2;
using geometry_detail::kClipperUnitsPerMm;
using geometry_detail::to_clipper;

namespace {

using ClipperLib::IntPoint;
using ClipperLib::Path;
using ClipperLib::Paths;

// Where two region boundaries coincide (a candidate touching the hole's ring at a corner, say),
// rounding the booleans to nm leaves needles ~1 nm wide whose corners are not feasible. The
// feasible region is eroded by this much before its corners are used: no needle survives, and
// every corner kept is this much inside.
constexpr double kNeedleMm = 3e-6;

struct Box {
  ClipperLib::cInt x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  ClipperLib::cInt dx() const { return x1 - x0; }
  ClipperLib::cInt dy() const { return y1 - y0; }
};
Box bounds(const Paths& paths) {
  Box b{INT64_MAX, INT64_MAX, INT64_MIN, INT64_MIN};
  for (const Path& p : paths)
    for (const IntPoint& q : p) {
      b.x0 = std::min(b.x0, q.X);
      b.y0 = std::min(b.y0, q.Y);
      b.x1 = std::max(b.x1, q.X);
      b.y1 = std::max(b.y1, q.Y);
    }
  return b;
}

Paths outer_rings(Paths paths) {
  std::erase_if(paths, [](const Path& p) { return !ClipperLib::Orientation(p); });
  return paths;
}

// Round growth as the tests measure it: chords within 1 µm of the arc.
Paths grow_round(const Path& ring, double by_mm) {
  ClipperLib::ClipperOffset off;
  off.ArcTolerance = 1e-3 * kClipperUnitsPerMm;
  off.AddPath(ring, ClipperLib::jtRound, ClipperLib::etClosedPolygon);
  Paths out;
  off.Execute(out, by_mm * kClipperUnitsPerMm);
  return out;
}

// A part rotated (no offset), in nm, and its outward proxy.
struct Rotated {
  Path real;
  Path proxy;
  Box box;
};

class HoleFiller {
 public:
  HoleFiller(std::span<const Part> parts, std::span<const int> group, const NestParams& params)
      : parts_(parts), group_(group.begin(), group.end()), params_(params), rotations_(method_rotations(params)) {
    const std::size_t n = parts.size();
    area_.assign(n, 0.0);
    hosted_.assign(n, false);
    has_children_.assign(n, false);
    cache_.resize(n);
    for (int p : group_) area_[p] = signed_area_mm2(parts[p].footprint_mm);
  }

  HoleFilling run() {
    std::vector<int> by_area = group_;
    std::stable_sort(by_area.begin(), by_area.end(), [&](int a, int b) { return area_[a] > area_[b]; });
    for (int host : by_area) {
      std::vector<const Polygon2*> holes;
      for (const Polygon2& h : parts_[host].free_holes_mm) holes.push_back(&h);
      std::stable_sort(holes.begin(), holes.end(),
                       [](const Polygon2* a, const Polygon2* b) { return signed_area_mm2(*a) > signed_area_mm2(*b); });
      for (const Polygon2* hole : holes) fill(host, *hole, by_area);
    }
    for (int p : group_)
      if (!hosted_[p]) out_.free.push_back(p);
    return std::move(out_);
  }

 private:
  const Rotated& rotated(int part, std::size_t r) {
    auto& slot = cache_[part];
    if (slot.empty()) slot.resize(rotations_.size());
    if (!slot[r]) {
      Placement at{part, rotations_[r], Eigen::Vector2d::Zero()};
      Rotated x;
      x.real = to_clipper(placed_footprint(parts_[part], at));
      x.proxy = outer_proxy(x.real);
      x.box = bounds({x.proxy});
      slot[r] = std::move(x);
    }
    return *slot[r];
  }

  void fill(int host, const Polygon2& hole_ring, const std::vector<int>& by_area) {
    const double s = params_.spacing_mm;
    const Path hole = to_clipper(hole_ring);
    const Paths room0 = offset_mitre({inner_proxy(hole)}, -(s + kSlackMm));
    if (room0.empty()) return;
    const Box room_box = bounds(room0);
    double room_area = area_mm2(room0);
    std::vector<Path> grown;  // children of this hole grown by the spacing (outward proxies)
    std::vector<Path> real;   // their footprints in the host's XY
    for (int cand : by_area) {
      if (cand == host || hosted_[cand] || has_children_[cand] || area_[cand] > room_area) continue;
      struct Best {
        IntPoint t;
        std::size_t r;
      };
      std::optional<Best> best;
      for (std::size_t r = 0; r < rotations_.size(); ++r) {
        const Rotated& c = rotated(cand, r);
        if (c.box.dx() > room_box.dx() || c.box.dy() > room_box.dy()) continue;
        Paths fit = inner_fit(room0, c.proxy);
        if (fit.empty()) continue;
        fit = offset_mitre(without_no_fit(fit, grown, c.proxy), -kNeedleMm);
        // Bottom-left: the lowest corner of the feasible region, then the leftmost.
        for (const Path& p : fit)
          for (const IntPoint& q : p)
            if (!best || q.Y < best->t.Y || (q.Y == best->t.Y && q.X < best->t.X)) best = Best{q, r};
      }
      if (!best) continue;
      const Rotated& c = rotated(cand, best->r);
      const Path placed = translated(c.real, best->t);
      if (!clear_of(placed, hole, real)) {
        ++out_.rejected_by_check;
        continue;
      }
      Placement in_host{cand, rotations_[best->r],
                        Eigen::Vector2d(static_cast<double>(best->t.X), static_cast<double>(best->t.Y)) / kClipperUnitsPerMm};
      out_.hosted.push_back({host, in_host});
      hosted_[cand] = true;
      has_children_[host] = true;
      if (params_.on_placed) params_.on_placed();
      for (Path& g : outer_rings(offset_mitre({translated(c.proxy, best->t)}, s + kSlackMm))) grown.push_back(std::move(g));
      real.push_back(placed);
      room_area = area_mm2(boolean(ClipperLib::ctDifference, room0, grown));
    }
  }

  // The real footprint at least the spacing (less 0.1 µm and the 1 µm chords) from the hole's
  // free ring and from every other child of the hole: the invariant the tests check.
  bool clear_of(const Path& placed, const Path& hole, const std::vector<Path>& others) const {
    const double by = params_.spacing_mm - 1e-4;
    const Paths zone = by > 0.0 ? grow_round(placed, by) : Paths{placed};
    if (area_mm2(boolean(ClipperLib::ctDifference, zone, {hole})) != 0.0) return false;
    for (const Path& o : others)
      if (area_mm2(boolean(ClipperLib::ctIntersection, zone, {o})) != 0.0) return false;
    return true;
  }

  std::span<const Part> parts_;
  std::vector<int> group_;
  const NestParams& params_;
  std::vector<double> rotations_;
  std::vector<double> area_;
  std::vector<bool> hosted_;
  std::vector<bool> has_children_;
  std::vector<std::vector<std::optional<Rotated>>> cache_;
  HoleFilling out_;
};

}  // namespace

HoleFilling fill_holes(std::span<const Part> parts, std::span<const int> group, const NestParams& params) {
  return HoleFiller(parts, group, params).run();
}

Placement compose(const Placement& host, const Placement& child) {
  Placement out = child;
  double a = std::fmod(host.rotation_rad + child.rotation_rad, 2.0 * std::numbers::pi);
  if (a < 0.0) a += 2.0 * std::numbers::pi;
  out.rotation_rad = a;
  out.offset_mm = rotation_matrix(host.rotation_rad) * child.offset_mm + host.offset_mm;
  out.host = -1;
  return out;
}

}  // namespace lamina::cam_detail
