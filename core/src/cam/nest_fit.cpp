// No-fit and inner-fit regions with Clipper 6 (see nest_fit.hpp for why each formula is exact).
#include "cam/nest_fit.hpp"

#include "geometry/ring_simplify.hpp"

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace lamina::cam_detail {
using geometry_detail::area_mm2;
using geometry_detail::kClipperUnitsPerMm;

using ClipperLib::IntPoint;
using ClipperLib::Path;
using ClipperLib::Paths;

namespace {

// Exact for any nm coordinates Clipper accepts (products need up to 2 × 62 bits).
__int128 cross(const IntPoint& o, const IntPoint& a, const IntPoint& b) {
  return static_cast<__int128>(a.X - o.X) * (b.Y - o.Y) - static_cast<__int128>(a.Y - o.Y) * (b.X - o.X);
}

constexpr std::size_t kProxyCorners = 64;

// How far a simplified concave proxy may stand off the ring it holds (between half this and 1.5
// times this): 50 µm, under the 64-gon's 60 µm on a Ø100 disc. The no-fit regions' cost grows
// with the product of both rings' corners, and a footprint's round-joined kerf offset has corners
// every few µm at its convex bends.
constexpr double kSimplifyMm = 0.05;

}  // namespace

Path convex_hull(Path pts) {
  std::sort(pts.begin(), pts.end(), [](const IntPoint& a, const IntPoint& b) {
    return a.X != b.X ? a.X < b.X : a.Y < b.Y;
  });
  pts.erase(std::unique(pts.begin(), pts.end()), pts.end());
  if (pts.size() < 3) return pts;
  Path h(2 * pts.size());
  std::size_t k = 0;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    while (k >= 2 && cross(h[k - 2], h[k - 1], pts[i]) <= 0) --k;
    h[k++] = pts[i];
  }
  for (std::size_t i = pts.size() - 1, t = k + 1; i-- > 0;) {
    while (k >= t && cross(h[k - 2], h[k - 1], pts[i]) <= 0) --k;
    h[k++] = pts[i];
  }
  h.resize(k - 1);
  return h;
}

Path circumscribed(const Path& hull, int k) {
  std::vector<Eigen::Vector2d> u(static_cast<std::size_t>(k));
  std::vector<double> h(static_cast<std::size_t>(k), -std::numeric_limits<double>::infinity());
  for (std::size_t j = 0; j < u.size(); ++j) {
    const double a = 2.0 * std::numbers::pi * static_cast<double>(j) / k;
    u[j] = {std::cos(a), std::sin(a)};
    for (const IntPoint& p : hull)
      h[j] = std::max(h[j], u[j].dot(Eigen::Vector2d(static_cast<double>(p.X), static_cast<double>(p.Y))));
  }
  Path out;
  for (std::size_t j = 0; j < u.size(); ++j) {
    const std::size_t n = (j + 1) % u.size();
    const Eigen::Vector2d& a = u[j];
    const Eigen::Vector2d& b = u[n];
    const double det = a.x() * b.y() - a.y() * b.x();
    const Eigen::Vector2d x((h[j] * b.y() - h[n] * a.y()) / det, (a.x() * h[n] - b.x() * h[j]) / det);
    out.emplace_back(static_cast<ClipperLib::cInt>(std::llround(x.x())), static_cast<ClipperLib::cInt>(std::llround(x.y())));
  }
  return out;
}

bool is_convex(const Path& ring) {
  const std::size_t n = ring.size();
  if (n < 3) return false;
  for (std::size_t i = 0; i < n; ++i)
    if (cross(ring[i], ring[(i + 1) % n], ring[(i + 2) % n]) < 0) return false;
  return true;
}

Path simplified_outside(const Path& ring) { return geometry_detail::simplified_beside(ring, kSimplifyMm); }
Path simplified_inside(const Path& ring) { return geometry_detail::simplified_beside(ring, -kSimplifyMm); }

Path outer_proxy(const Path& ring) {
  Path hull = convex_hull(ring);
  if (hull.size() < 3 || ClipperLib::Area(hull) > 1.02 * std::abs(ClipperLib::Area(ring)))
    return simplified_outside(ring);
  return hull.size() > kProxyCorners ? circumscribed(hull, static_cast<int>(kProxyCorners)) : hull;
}

namespace {

// How far the ring's corners lie inside its convex hull at most: every pocket of the ring lies
// under one hull edge, within the strip its corners span, so the hull eroded by this lies inside
// the ring. (Faceted round holes come out of the slicer and Clipper a few nm off convex.)
double pocket_depth(const Path& ring, const Path& hull) {
  double depth = 0.0;
  for (const IntPoint& p : ring) {
    double nearest = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < hull.size(); ++i) {
      const IntPoint& a = hull[i];
      const IntPoint& b = hull[(i + 1) % hull.size()];
      const double ex = static_cast<double>(b.X - a.X), ey = static_cast<double>(b.Y - a.Y);
      const double len = std::hypot(ex, ey);
      if (len == 0.0) continue;
      // Inside the CCW hull the cross product is ≥ 0: the distance to the edge's line.
      nearest = std::min(nearest, (ex * static_cast<double>(p.Y - a.Y) - ey * static_cast<double>(p.X - a.X)) / len);
    }
    depth = std::max(depth, nearest);
  }
  return depth;
}

}  // namespace

Path inner_proxy(const Path& ring) {
  if (ring.size() <= kProxyCorners) return ring;
  Path convex = ring;
  if (!is_convex(ring)) {
    // Nearly convex (pockets under 0.1 % of the hull's size): the hull eroded by the deepest pocket.
    const Path hull = convex_hull(ring);
    if (hull.size() < 3) return ring;
    const double depth = pocket_depth(ring, hull);
    const double size = std::sqrt(std::abs(ClipperLib::Area(hull)));
    if (depth > 1e-3 * size) return simplified_inside(ring);
    ClipperLib::ClipperOffset off;
    off.AddPath(hull, ClipperLib::jtMiter, ClipperLib::etClosedPolygon);
    Paths eroded;
    off.Execute(eroded, -(depth + 2.0));  // + 2 nm: the offset's own rounding
    if (eroded.size() != 1 || !ClipperLib::Orientation(eroded.front())) return ring;
    convex = std::move(eroded.front());
    if (convex.size() <= kProxyCorners) return convex;
  }
  // Corners of a convex ring evenly picked: their hull lies in any convex set holding them.
  Path out;
  for (std::size_t i = 0; i < kProxyCorners; ++i) out.push_back(convex[i * convex.size() / kProxyCorners]);
  return out;
}

Path translated(const Path& ring, IntPoint by) {
  Path out;
  out.reserve(ring.size());
  for (const IntPoint& p : ring) out.emplace_back(p.X + by.X, p.Y + by.Y);
  return out;
}

Path negated(const Path& ring) {
  Path out;
  out.reserve(ring.size());
  for (const IntPoint& p : ring) out.emplace_back(-p.X, -p.Y);
  return out;  // a point reflection keeps the turning sense
}

Paths minkowski_sum(const Path& a, const Path& b) {
  if (a.empty() || b.empty()) return {};
  if (is_convex(a) && is_convex(b)) {
    Path sums;
    sums.reserve(a.size() * b.size());
    for (const IntPoint& p : a)
      for (const IntPoint& q : b) sums.emplace_back(p.X + q.X, p.Y + q.Y);
    Path hull = convex_hull(std::move(sums));
    return hull.size() >= 3 ? Paths{hull} : Paths{};
  }
  Paths quads;
  ClipperLib::MinkowskiSum(b, a, quads, true);
  return boolean(ClipperLib::ctUnion, quads, {translated(a, b.front()), translated(b, a.front())});
}

namespace {

struct BoxWindow {
  ClipperLib::cInt x0 = INT64_MAX, y0 = INT64_MAX, x1 = INT64_MIN, y1 = INT64_MIN;
  void add(const IntPoint& p) {
    x0 = std::min(x0, p.X);
    y0 = std::min(y0, p.Y);
    x1 = std::max(x1, p.X);
    y1 = std::max(y1, p.Y);
  }
  bool meets(const BoxWindow& o) const { return x0 <= o.x1 && o.x0 <= x1 && y0 <= o.y1 && o.y0 <= y1; }
};

BoxWindow window_of(const Path& ring) {
  BoxWindow w;
  for (const IntPoint& p : ring) w.add(p);
  return w;
}

// The parallelograms ∂A ⊕ ∂B, edge by edge, whose bounds meet `window` (counter-clockwise; a pair
// of parallel edges gives a segment, covered by its neighbours' sides, and is left out).
void edge_parallelograms(const Path& a, const Path& b, const BoxWindow& window, Paths& out) {
  for (std::size_t i = 0; i < a.size(); ++i) {
    const IntPoint& p = a[i];
    const IntPoint& q = a[(i + 1) % a.size()];
    // Pairs whose bounds cannot meet the window are skipped before a parallelogram is made.
    const BoxWindow edge{std::min(p.X, q.X), std::min(p.Y, q.Y), std::max(p.X, q.X), std::max(p.Y, q.Y)};
    for (std::size_t j = 0; j < b.size(); ++j) {
      const IntPoint& u = b[j];
      const IntPoint& v = b[(j + 1) % b.size()];
      const BoxWindow sum{edge.x0 + std::min(u.X, v.X), edge.y0 + std::min(u.Y, v.Y), edge.x1 + std::max(u.X, v.X),
                          edge.y1 + std::max(u.Y, v.Y)};
      if (!sum.meets(window)) continue;
      Path quad{{p.X + u.X, p.Y + u.Y}, {q.X + u.X, q.Y + u.Y}, {q.X + v.X, q.Y + v.Y}, {p.X + v.X, p.Y + v.Y}};
      const double area = ClipperLib::Area(quad);
      if (area == 0.0) continue;
      if (area < 0.0) ClipperLib::ReversePath(quad);
      out.push_back(std::move(quad));
    }
  }
}

// The pieces of G ⊕ (−C) (as minkowski_sum) that may meet `window`: the hull when both are
// convex, else the edge-pair parallelograms whose bounds meet it, with G − c0 and −C + g0.
void no_fit_pieces(const Path& g, const Path& neg, const BoxWindow& window, Paths& out) {
  if (is_convex(g) && is_convex(neg)) {
    for (Path& p : minkowski_sum(g, neg)) out.push_back(std::move(p));
    return;
  }
  for (Path ring : {translated(g, neg.front()), translated(neg, g.front())})
    if (window_of(ring).meets(window)) out.push_back(std::move(ring));
  edge_parallelograms(g, neg, window, out);
}

// Where C's corners alone may go: {t : c + t in the room} for a few corners c of C spread round
// its hull (c0 among them), i.e. the room moved by −c for each, intersected. Every t that puts
// all of C in the room is in it, so it bounds the inner-fit region; for a C that nearly fills a
// room it is a small patch, or nothing.
Paths corners_fit(const Paths& room, const Path& c) {
  constexpr std::size_t kCorners = 16;
  auto room_less = [&](const IntPoint& q) {
    Paths moved;
    for (const Path& r : room) moved.push_back(translated(r, {-q.X, -q.Y}));
    return moved;
  };
  Paths where = room_less(c.front());
  const Path hull = convex_hull(c);
  const std::size_t picked = std::min(kCorners, hull.size());
  for (std::size_t i = 0; i < picked && !where.empty(); ++i)
    where = boolean(ClipperLib::ctIntersection, where, room_less(hull[i * hull.size() / picked]));
  return where;
}

}  // namespace

Paths without_no_fit(const Paths& fit, const std::vector<Path>& children, const Path& c) {
  if (fit.empty() || children.empty()) return fit;
  BoxWindow window;
  for (const Path& p : fit)
    for (const IntPoint& q : p) window.add(q);
  // Only what meets the fit region's bounds can take anything from it: for a candidate that
  // nearly fills its hole that is a small share of the |G| × |C| parallelograms, and one
  // difference with all of them (non-zero rule) replaces a union per child.
  const Path neg = negated(c);
  Paths blocked;
  for (const Path& g : children) no_fit_pieces(g, neg, window, blocked);
  if (blocked.empty()) return fit;
  return boolean(ClipperLib::ctDifference, fit, blocked);
}

Paths inner_fit_general(const Paths& room, const Path& c) {
  if (c.empty()) return {};
  // The region lies within where C's corners may go: only the pieces that meet its bounds can
  // take anything from it (the Menger sponge's layers: 136-corner rooms, 363-corner candidates
  // nearly filling them, 49 000 parallelograms united per call, minutes of hole filling).
  const Paths where = corners_fit(room, c);
  if (where.empty()) return {};
  BoxWindow window;
  for (const Path& p : where)
    for (const IntPoint& q : p) window.add(q);
  const Path neg = negated(c);
  Paths blocked;
  for (const Path& r : room) {
    if (r.size() < 3) continue;
    if (Path inside = translated(neg, r.front()); window_of(inside).meets(window)) blocked.push_back(std::move(inside));
    edge_parallelograms(r, neg, window, blocked);
  }
  if (blocked.empty()) return where;
  return boolean(ClipperLib::ctDifference, where, blocked);
}

Paths inner_fit(const Paths& room, const Path& c) {
  if (room.size() != 1 || !is_convex(room.front())) return inner_fit_general(room, c);
  // A convex room holds C exactly when it holds C's hull: the shortcut below is exact for a
  // concave C too, and the general formula's |room| × |C| parallelograms are not needed.
  if (!is_convex(c)) return inner_fit(room, convex_hull(c));
  // C + t lies left of room edge (p, p + e) iff its corner c* of least e × c does: the edge moved by −c*.
  const Path& r = room.front();
  using V = Eigen::Vector2d;
  auto v = [](const IntPoint& p) { return V(static_cast<double>(p.X), static_cast<double>(p.Y)); };
  auto cr = [](const V& a, const V& b) { return a.x() * b.y() - a.y() * b.x(); };
  std::vector<V> poly;
  for (const IntPoint& p : r) poly.push_back(v(p) - v(c.front()));
  for (std::size_t i = 0; i < r.size() && !poly.empty(); ++i) {
    const V e = v(r[(i + 1) % r.size()]) - v(r[i]);
    if (e.squaredNorm() == 0.0) continue;
    const IntPoint* best = &c.front();
    for (const IntPoint& q : c)
      if (cr(e, v(q)) < cr(e, v(*best))) best = &q;
    const V q0 = v(r[i]) - v(*best);
    std::vector<V> next;  // Sutherland–Hodgman against one line
    for (std::size_t k = 0; k < poly.size(); ++k) {
      const V& a = poly[k];
      const V& b = poly[(k + 1) % poly.size()];
      const double da = cr(e, a - q0);
      const double db = cr(e, b - q0);
      if (da >= 0.0) next.push_back(a);
      if ((da >= 0.0) != (db >= 0.0)) next.push_back(a + (b - a) * (da / (da - db)));
    }
    poly = std::move(next);
  }
  Path out;
  for (const V& p : poly) {
    const IntPoint q{static_cast<ClipperLib::cInt>(std::llround(p.x())), static_cast<ClipperLib::cInt>(std::llround(p.y()))};
    if (out.empty() || !(out.back() == q)) out.push_back(q);
  }
  while (out.size() > 1 && out.back() == out.front()) out.pop_back();
  if (out.size() < 3 || ClipperLib::Area(out) <= 0.0) return {};
  return {out};
}

}  // namespace lamina::cam_detail
