// Ear clipping with hole bridges (Eberly, "Triangulation by Ear Clipping"; the bridge search and
// the local-inside tests follow mapbox/earcut, mirrored to a ray towards +x). Unlike earcut,
// nothing is filtered: coincident and collinear points stay, because the caller's walls use them.
#include "polygon_triangulation.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

namespace lamina::detail {
namespace {

// A corner whose turn has a smaller sine than this counts as straight when looking for ears:
// cutting it would leave a sliver that rounding to float (STL) can flatten to zero area.
constexpr double kStraightSine = 1e-7;
// Polygons from this many vertices on get a grid for their ear tests.
constexpr std::size_t kGridFrom = 64;

struct Node {
  double x = 0.0, y = 0.0;
  std::int32_t index = 0;  // vertex number in the caller's numbering
  std::int32_t prev = -1, next = -1;
};

class Triangulator {
 public:
  std::vector<Node> nodes;
  std::vector<std::array<std::int32_t, 3>> out;
  // A uniform grid of the nodes (built once the holes are bridged) for the ear tests of large
  // polygons; removed nodes stay in it, marked dead.
  std::vector<char> alive;
  std::vector<std::uint32_t> cell_begin, cell_items;
  double grid_x0 = 0.0, grid_y0 = 0.0, cell = 1.0;
  int grid_nx = 0, grid_ny = 0;

  // Links ring vertices first..first+n−1 (numbered from `first_index`) in the wanted
  // orientation; returns a node of the ring.
  std::int32_t link_ring(const Polygon2& ring, std::int32_t first_index, bool want_ccw) {
    const auto n = static_cast<std::int32_t>(ring.size());
    const bool reverse = (signed_area_mm2(ring) > 0.0) != want_ccw;
    const auto base = static_cast<std::int32_t>(nodes.size());
    for (std::int32_t i = 0; i < n; ++i) {
      Node node;
      node.x = ring[static_cast<std::size_t>(i)].x();
      node.y = ring[static_cast<std::size_t>(i)].y();
      node.index = first_index + i;
      nodes.push_back(node);
    }
    for (std::int32_t i = 0; i < n; ++i) {
      Node& node = nodes[static_cast<std::size_t>(base + i)];
      const std::int32_t nx = base + (i + 1) % n, pv = base + (i + n - 1) % n;
      node.next = reverse ? pv : nx;
      node.prev = reverse ? nx : pv;
    }
    return base;
  }

  const Node& at(std::int32_t i) const { return nodes[static_cast<std::size_t>(i)]; }
  Node& at(std::int32_t i) { return nodes[static_cast<std::size_t>(i)]; }

  // (q − p) × (r − p): > 0 when p, q, r turn left.
  double orient(std::int32_t p, std::int32_t q, std::int32_t r) const {
    const Node &a = at(p), &b = at(q), &c = at(r);
    return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
  }
  bool same_point(std::int32_t p, std::int32_t q) const { return at(p).x == at(q).x && at(p).y == at(q).y; }

  // Is the diagonal a → b inside the polygon near a (in the wedge of a's two edges)?
  bool locally_inside(std::int32_t a, std::int32_t b) const {
    const std::int32_t ap = at(a).prev, an = at(a).next;
    if (orient(ap, a, an) > 0.0) return orient(a, b, an) <= 0.0 && orient(a, ap, b) <= 0.0;
    return orient(a, b, ap) > 0.0 || orient(a, an, b) > 0.0;
  }
  // Does m's wedge contain p's (for picking among coincident copies of a bridge vertex)?
  bool sector_contains_sector(std::int32_t m, std::int32_t p) const {
    return orient(at(m).prev, m, at(p).prev) > 0.0 && orient(at(p).next, m, at(m).next) > 0.0;
  }

  static bool in_triangle(double ax, double ay, double bx, double by, double cx, double cy, double px, double py) {
    return (bx - ax) * (py - ay) - (by - ay) * (px - ax) >= 0.0 && (cx - bx) * (py - by) - (cy - by) * (px - bx) >= 0.0 &&
           (ax - cx) * (py - cy) - (ay - cy) * (px - cx) >= 0.0;
  }

  // The vertex of the outer list that the hole vertex h can be joined to (ray towards +x).
  std::int32_t find_bridge(std::int32_t h, std::int32_t outer) const {
    const double hx = at(h).x, hy = at(h).y;
    double qx = std::numeric_limits<double>::infinity();
    std::int32_t m = -1;
    std::int32_t p = outer;
    do {
      const std::int32_t pn = at(p).next;
      if (same_point(h, p)) return p;
      if (hy >= at(p).y && hy <= at(pn).y && at(pn).y != at(p).y) {
        const double x = at(p).x + (hy - at(p).y) * (at(pn).x - at(p).x) / (at(pn).y - at(p).y);
        if (x >= hx && x < qx) {
          qx = x;
          m = at(p).x > at(pn).x ? p : pn;
          if (x == hx) return m;  // the hole touches this edge
        }
      }
      p = pn;
    } while (p != outer);
    if (m < 0) return -1;

    // Reflex vertices inside the triangle (hole point, ray hit, m) hide m: take the one closest
    // in angle to the ray instead.
    const std::int32_t stop = m;
    const double mx = at(m).x, my = at(m).y;
    double tan_min = std::numeric_limits<double>::infinity();
    p = m;
    do {
      const Node& pp = at(p);
      if (hx <= pp.x && pp.x <= mx && hx != pp.x &&
          in_triangle(hy < my ? qx : hx, hy, mx, my, hy < my ? hx : qx, hy, pp.x, pp.y)) {
        const double tan = std::abs(hy - pp.y) / (pp.x - hx);
        if (locally_inside(p, h) &&
            (tan < tan_min || (tan == tan_min && (pp.x < at(m).x || (pp.x == at(m).x && sector_contains_sector(m, p)))))) {
          m = p;
          tan_min = tan;
        }
      }
      p = pp.next;
    } while (p != stop);
    return m;
  }

  // Joins a → b with a bridge: a → b … (b's ring) … b' → a' → (a's old next).
  void split(std::int32_t a, std::int32_t b) {
    Node a2 = at(a), b2 = at(b);
    const auto ia2 = static_cast<std::int32_t>(nodes.size());
    const std::int32_t ib2 = ia2 + 1;
    nodes.push_back(a2);
    nodes.push_back(b2);
    const std::int32_t an = at(a).next, bp = at(b).prev;
    at(a).next = b;
    at(b).prev = a;
    at(ia2).next = an;
    at(an).prev = ia2;
    at(ib2).next = ia2;
    at(ia2).prev = ib2;
    at(bp).next = ib2;
    at(ib2).prev = bp;
  }

  void emit(std::int32_t a, std::int32_t b, std::int32_t c) {
    const std::int32_t ia = at(a).index, ib = at(b).index, ic = at(c).index;
    if (ia == ib || ib == ic || ia == ic) return;  // the two copies of a bridge end: a fold, no area
    out.push_back({ia, ib, ic});
  }

  void remove(std::int32_t i) {
    at(at(i).prev).next = at(i).next;
    at(at(i).next).prev = at(i).prev;
    alive[static_cast<std::size_t>(i)] = 0;
  }

  int cell_x(double x) const { return std::clamp(static_cast<int>((x - grid_x0) / cell), 0, grid_nx - 1); }
  int cell_y(double y) const { return std::clamp(static_cast<int>((y - grid_y0) / cell), 0, grid_ny - 1); }

  void build_grid(std::int32_t start, std::size_t count) {
    alive.assign(nodes.size(), 0);
    double x0 = std::numeric_limits<double>::infinity(), y0 = x0, x1 = -x0, y1 = -x0;
    std::int32_t p = start;
    do {
      alive[static_cast<std::size_t>(p)] = 1;
      x0 = std::min(x0, at(p).x);
      x1 = std::max(x1, at(p).x);
      y0 = std::min(y0, at(p).y);
      y1 = std::max(y1, at(p).y);
      p = at(p).next;
    } while (p != start);
    if (count < kGridFrom) return;
    const double w = std::max(x1 - x0, 1e-300), h = std::max(y1 - y0, 1e-300);
    cell = std::max(std::sqrt(w * h / static_cast<double>(count)), std::max(w, h) / 2048.0);
    grid_nx = std::clamp(static_cast<int>(w / cell) + 1, 1, 2048);
    grid_ny = std::clamp(static_cast<int>(h / cell) + 1, 1, 2048);
    grid_x0 = x0;
    grid_y0 = y0;
    cell_begin.assign(static_cast<std::size_t>(grid_nx) * static_cast<std::size_t>(grid_ny) + 1, 0);
    auto cell_of = [&](std::int32_t q) {
      return static_cast<std::size_t>(cell_y(at(q).y)) * static_cast<std::size_t>(grid_nx) +
             static_cast<std::size_t>(cell_x(at(q).x));
    };
    p = start;
    do {
      ++cell_begin[cell_of(p) + 1];
      p = at(p).next;
    } while (p != start);
    for (std::size_t c = 0; c + 1 < cell_begin.size(); ++c) cell_begin[c + 1] += cell_begin[c];
    cell_items.resize(cell_begin.back());
    std::vector<std::uint32_t> fill(cell_begin.begin(), cell_begin.end() - 1);
    p = start;
    do {
      cell_items[fill[cell_of(p)]++] = static_cast<std::uint32_t>(p);
      p = at(p).next;
    } while (p != start);
  }

  // A node p (not a, e, c) that blocks the ear (a, e, c): inside or on the triangle, not at one
  // of its corners, and (in strict mode) not convex.
  bool blocks(std::int32_t p, std::int32_t a, std::int32_t e, std::int32_t c, bool strict) const {
    const Node &na = at(a), &nb = at(e), &nc = at(c), &np = at(p);
    if (same_point(p, a) || same_point(p, e) || same_point(p, c)) return false;
    if (!in_triangle(na.x, na.y, nb.x, nb.y, nc.x, nc.y, np.x, np.y)) return false;
    // Only a corner that is not convex can poke into an ear of a simple polygon.
    return !strict || orient(np.prev, p, np.next) <= 0.0;
  }

  bool is_ear(std::int32_t e, bool strict) const {
    const std::int32_t a = at(e).prev, c = at(e).next;
    const Node &na = at(a), &nb = at(e), &nc = at(c);
    const double turn = orient(a, e, c);
    if (strict) {
      const double la = std::hypot(nb.x - na.x, nb.y - na.y), lc = std::hypot(nc.x - nb.x, nc.y - nb.y);
      if (!(turn > kStraightSine * la * lc)) return false;
    } else if (!(turn > 0.0)) {
      return false;
    }
    const double x0 = std::min({na.x, nb.x, nc.x}), x1 = std::max({na.x, nb.x, nc.x});
    const double y0 = std::min({na.y, nb.y, nc.y}), y1 = std::max({na.y, nb.y, nc.y});
    if (grid_nx == 0) {
      for (std::int32_t p = at(c).next; p != a; p = at(p).next) {
        const Node& np = at(p);
        if (np.x < x0 || np.x > x1 || np.y < y0 || np.y > y1) continue;
        if (blocks(p, a, e, c, strict)) return false;
      }
      return true;
    }
    const int cx0 = cell_x(x0), cx1 = cell_x(x1), cy0 = cell_y(y0), cy1 = cell_y(y1);
    for (int cy = cy0; cy <= cy1; ++cy)
      for (int cx = cx0; cx <= cx1; ++cx) {
        const std::size_t cell_index = static_cast<std::size_t>(cy) * static_cast<std::size_t>(grid_nx) + static_cast<std::size_t>(cx);
        for (std::uint32_t k = cell_begin[cell_index]; k < cell_begin[cell_index + 1]; ++k) {
          const auto p = static_cast<std::int32_t>(cell_items[k]);
          if (!alive[static_cast<std::size_t>(p)] || p == a || p == e || p == c) continue;
          const Node& np = at(p);
          if (np.x < x0 || np.x > x1 || np.y < y0 || np.y > y1) continue;
          if (blocks(p, a, e, c, strict)) return false;
        }
      }
    return true;
  }

  void clip(std::int32_t start, std::size_t count) {
    std::int32_t ear = start, stop = start;
    int pass = 0;
    while (count > 3) {
      const std::int32_t prev = at(ear).prev, next = at(ear).next;
      bool cut = false;
      if (at(ear).index == at(next).index) {
        cut = true;  // two copies of one vertex in a row: drop one, no triangle
      } else if (same_point(ear, next) || (pass == 0 && is_ear(ear, true)) || (pass == 1 && is_ear(ear, false))) {
        emit(prev, ear, next);
        cut = true;
      }
      if (cut) {
        remove(ear);
        --count;
        ear = stop = next;
        pass = 0;
        continue;
      }
      ear = next;
      if (ear != stop) continue;
      if (pass < 2) {
        ++pass;
        continue;
      }
      // No ear at all (self-touching or numerically flat input): cut the most convex corner.
      std::int32_t best = ear;
      double best_turn = -std::numeric_limits<double>::infinity();
      std::int32_t p = ear;
      do {
        const double turn = orient(at(p).prev, p, at(p).next);
        if (turn > best_turn) {
          best_turn = turn;
          best = p;
        }
        p = at(p).next;
      } while (p != ear);
      emit(at(best).prev, best, at(best).next);
      const std::int32_t after = at(best).next;
      remove(best);
      --count;
      ear = stop = after;
      pass = 0;
    }
    if (count == 3) emit(at(ear).prev, ear, at(ear).next);
  }
};

}  // namespace

std::vector<std::array<std::int32_t, 3>> triangulate_polygon_with_holes(const Polygon2& outer,
                                                                        const std::vector<Polygon2>& holes) {
  if (outer.size() < 3) return {};
  Triangulator tri;
  std::size_t total = outer.size();
  for (const auto& h : holes) total += h.size();
  tri.nodes.reserve(total + 2 * holes.size());
  const std::int32_t outer_node = tri.link_ring(outer, 0, true);
  std::size_t count = outer.size();

  // Each hole's rightmost vertex, holes right to left.
  struct HoleStart {
    std::int32_t node;
    double x, y;
  };
  std::vector<HoleStart> starts;
  auto first_index = static_cast<std::int32_t>(outer.size());
  for (const auto& h : holes) {
    if (h.size() >= 3) {
      const std::int32_t base = tri.link_ring(h, first_index, false);
      std::int32_t right = base;
      for (std::int32_t i = base; i < base + static_cast<std::int32_t>(h.size()); ++i) {
        const Node& n = tri.at(i);
        if (n.x > tri.at(right).x || (n.x == tri.at(right).x && n.y < tri.at(right).y)) right = i;
      }
      starts.push_back({right, tri.at(right).x, tri.at(right).y});
    }
    first_index += static_cast<std::int32_t>(h.size());
  }
  std::stable_sort(starts.begin(), starts.end(),
                   [](const HoleStart& a, const HoleStart& b) { return a.x > b.x || (a.x == b.x && a.y < b.y); });

  for (const auto& s : starts) {
    std::int32_t bridge = tri.find_bridge(s.node, outer_node);
    if (bridge < 0) {
      // No edge to the right (the hole is not inside): join it to the nearest outer-list vertex.
      double best = std::numeric_limits<double>::infinity();
      std::int32_t p = outer_node;
      do {
        const double d = std::hypot(tri.at(p).x - s.x, tri.at(p).y - s.y);
        if (d < best) {
          best = d;
          bridge = p;
        }
        p = tri.at(p).next;
      } while (p != outer_node);
    }
    const std::size_t hole_size = [&] {
      std::size_t n = 0;
      std::int32_t p = s.node;
      do {
        ++n;
        p = tri.at(p).next;
      } while (p != s.node);
      return n;
    }();
    tri.split(bridge, s.node);
    count += hole_size + 2;
  }
  tri.out.reserve(count - 2);
  tri.build_grid(outer_node, count);
  tri.clip(outer_node, count);
  return std::move(tri.out);
}

}  // namespace lamina::detail
