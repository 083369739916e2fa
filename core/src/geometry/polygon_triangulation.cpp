// Ear clipping with hole bridges (Eberly, "Triangulation by Ear Clipping"; the bridge search and
// the local-inside tests follow mapbox/earcut, mirrored to a ray towards +x). Unlike earcut,
// nothing is filtered: coincident and collinear points stay, because the caller's walls use them.
//
// Large rings (kTreeFrom vertices on) are clipped in about linear time. The strict ear test looks
// only at the corners that are not convex, through a 2-d tree they leave once convex or cut: in a
// simple polygon a triangle holding any vertex holds a reflex one, and cutting an ear never makes
// a convex corner reflex. After each cut the walk skips a corner, so the triangles stay local
// rather than fanning out from one corner (a fan's long triangles cover many corners' boxes), and
// ears too low for float wait until nothing else is left. A step budget bounds what degenerate
// input can cost: past it the rest is cut corner by corner.
#include "geometry/polygon_triangulation.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <deque>
#include <limits>
#include <numeric>

namespace lamina::geometry_detail {
namespace {

// Polygons from this many vertices on get trees for their ear tests.
constexpr std::size_t kTreeFrom = 64;
// Large rings cut an ear lower than this many float steps of the ring's coordinates (its
// height over its longest side) only when no other ear is left: stack.stl stores float, and
// rounding would flatten it to a sliver with no area, opening the stack.
constexpr double kThinEarFloatSteps = 64.0;

struct Node {
  double x = 0.0, y = 0.0;
  std::int32_t index = 0;  // vertex number in the caller's numbering
  std::int32_t prev = -1, next = -1;
};

// A triangle (counter-clockwise) as its corners' coordinates: ax ay bx by cx cy.
using Triangle2 = std::array<double, 6>;

// A 2-d tree over a set of nodes (median splits, stored in one array) from which nodes can be
// erased. A query visits only the subtrees whose bounding box meets the triangle and that still
// hold a node, so it costs about the nodes near the triangle, however they crowd along the ring.
class NodeTree {
 public:
  bool built() const { return built_; }

  void build(const std::vector<Node>& nodes, const std::vector<std::int32_t>& members) {
    built_ = true;
    items_.clear();
    for (const std::int32_t q : members) {
      const Node& n = nodes[static_cast<std::size_t>(q)];
      items_.push_back({n.x, n.y, q});
    }
    where_.assign(nodes.size(), -1);
    gone_.assign(items_.size(), 0);
    alive_.assign(items_.size(), 0);
    box_.assign(items_.size(), {});
    if (!items_.empty()) split(0, items_.size(), 0);
    for (std::size_t i = 0; i < items_.size(); ++i) where_[static_cast<std::size_t>(items_[i].node)] = static_cast<std::int32_t>(i);
  }

  void erase(std::int32_t node) {
    if (static_cast<std::size_t>(node) >= where_.size() || where_[static_cast<std::size_t>(node)] < 0) return;
    const auto i = static_cast<std::size_t>(where_[static_cast<std::size_t>(node)]);
    if (gone_[i]) return;
    gone_[i] = 1;
    std::size_t lo = 0, hi = items_.size();
    while (hi - lo > kLeaf) {
      const std::size_t mid = lo + (hi - lo) / 2;
      --alive_[mid];
      if (i == mid) return;
      if (i < mid) hi = mid;
      else lo = mid + 1;
    }
    --alive_[lo];
  }

  // True when f(node) is true for a node (not erased) whose subtree's box meets the triangle;
  // each subtree and node looked at counts a step.
  template <class F>
  bool any_near(const Triangle2& t, std::uint64_t& steps, F&& f) const {
    return !items_.empty() && visit(0, items_.size(), t, steps, f);
  }

 private:
  struct Item {
    double x, y;
    std::int32_t node;
  };
  using Box = std::array<double, 4>;  // x0 y0 x1 y1
  static constexpr std::size_t kLeaf = 8;

  // Orders items_[lo, hi) about its median on x (even depth) or y, recursively; alive_ and box_
  // hold each subtree's count and bounds at its median (at lo for a leaf). Returns the bounds.
  Box split(std::size_t lo, std::size_t hi, int depth) {
    if (hi - lo <= kLeaf) {
      Box b{items_[lo].x, items_[lo].y, items_[lo].x, items_[lo].y};
      for (std::size_t i = lo; i < hi; ++i) b = grown(b, items_[i]);
      alive_[lo] = static_cast<std::uint32_t>(hi - lo);
      return box_[lo] = b;
    }
    const std::size_t mid = lo + (hi - lo) / 2;
    const bool by_x = depth % 2 == 0;
    std::nth_element(items_.begin() + static_cast<std::ptrdiff_t>(lo), items_.begin() + static_cast<std::ptrdiff_t>(mid),
                     items_.begin() + static_cast<std::ptrdiff_t>(hi),
                     [by_x](const Item& a, const Item& b) { return by_x ? a.x < b.x : a.y < b.y; });
    const Box l = split(lo, mid, depth + 1), r = split(mid + 1, hi, depth + 1);
    alive_[mid] = static_cast<std::uint32_t>(hi - lo);
    return box_[mid] = grown({std::min(l[0], r[0]), std::min(l[1], r[1]), std::max(l[2], r[2]), std::max(l[3], r[3])},
                             items_[mid]);
  }

  static Box grown(const Box& b, const Item& it) {
    return {std::min(b[0], it.x), std::min(b[1], it.y), std::max(b[2], it.x), std::max(b[3], it.y)};
  }

  // False only when the box surely misses the (closed) triangle: apart from its bounds, or wholly
  // to the right of one of its edges.
  static bool meets(const Box& b, const Triangle2& t) {
    if (b[0] > std::max({t[0], t[2], t[4]}) || b[2] < std::min({t[0], t[2], t[4]}) ||
        b[1] > std::max({t[1], t[3], t[5]}) || b[3] < std::min({t[1], t[3], t[5]}))
      return false;
    for (int k = 0; k < 3; ++k) {
      const double px = t[2 * k], py = t[2 * k + 1], qx = t[(2 * k + 2) % 6], qy = t[(2 * k + 3) % 6];
      const auto right = [&](double x, double y) { return (qx - px) * (y - py) - (qy - py) * (x - px) < 0.0; };
      if (right(b[0], b[1]) && right(b[2], b[1]) && right(b[0], b[3]) && right(b[2], b[3])) return false;
    }
    return true;
  }

  template <class F>
  bool visit(std::size_t lo, std::size_t hi, const Triangle2& t, std::uint64_t& steps, F& f) const {
    ++steps;
    const bool leaf = hi - lo <= kLeaf;
    const std::size_t key = leaf ? lo : lo + (hi - lo) / 2;
    if (alive_[key] == 0 || !meets(box_[key], t)) return false;
    if (leaf) {
      for (std::size_t i = lo; i < hi; ++i, ++steps)
        if (!gone_[i] && f(items_[i].node)) return true;
      return false;
    }
    if (!gone_[key] && f(items_[key].node)) return true;
    return (key > lo && visit(lo, key, t, steps, f)) || (key + 1 < hi && visit(key + 1, hi, t, steps, f));
  }

  bool built_ = false;
  std::vector<Item> items_;
  std::vector<std::int32_t> where_;  // node → its place in items_, or −1
  std::vector<char> gone_;
  std::vector<std::uint32_t> alive_;
  std::vector<Box> box_;
};

class Triangulator {
 public:
  double straight_sine = kCapStraightSine;
  std::vector<Node> nodes;
  std::vector<std::array<std::int32_t, 3>> out;
  // Which nodes are still in the ring, and (large rings) trees of them and of those that are not
  // convex, for the loose and the strict ear test.
  std::vector<char> alive;
  NodeTree all_tree, reflex_tree;
  bool use_trees = false;
  std::uint64_t steps = 0, budget = 0;
  bool exhausted = false;
  double thin_height = 0.0;  // see kThinEarFloatSteps

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

  // Links the holes (numbered from first_index) and joins each to the outer list by a bridge,
  // rightmost hole first; returns how many nodes that added to the ring.
  std::size_t bridge_holes(std::int32_t outer_node, const std::vector<Polygon2>& holes, std::int32_t first_index) {
    struct HoleStart {
      std::int32_t node;
      double x, y;
      std::size_t size;
    };
    std::vector<HoleStart> starts;
    for (const auto& h : holes) {
      if (h.size() >= 3) {
        const std::int32_t base = link_ring(h, first_index, false);
        std::int32_t right = base;
        for (std::int32_t i = base; i < base + static_cast<std::int32_t>(h.size()); ++i) {
          const Node& n = at(i);
          if (n.x > at(right).x || (n.x == at(right).x && n.y < at(right).y)) right = i;
        }
        starts.push_back({right, at(right).x, at(right).y, h.size()});
      }
      first_index += static_cast<std::int32_t>(h.size());
    }
    std::stable_sort(starts.begin(), starts.end(),
                     [](const HoleStart& a, const HoleStart& b) { return a.x > b.x || (a.x == b.x && a.y < b.y); });
    std::size_t added = 0;
    for (const auto& s : starts) {
      std::int32_t bridge = find_bridge(s.node, outer_node);
      if (bridge < 0) {
        // No edge to the right (the hole is not inside): join it to the nearest outer-list vertex.
        double best = std::numeric_limits<double>::infinity();
        std::int32_t p = outer_node;
        do {
          const double d = std::hypot(at(p).x - s.x, at(p).y - s.y);
          if (d < best) {
            best = d;
            bridge = p;
          }
          p = at(p).next;
        } while (p != outer_node);
      }
      split(bridge, s.node);
      added += s.size + 2;
    }
    return added;
  }

  void remove(std::int32_t i) {
    const std::int32_t p = at(i).prev, n = at(i).next;
    at(p).next = n;
    at(n).prev = p;
    alive[static_cast<std::size_t>(i)] = 0;
    if (!use_trees) return;
    if (all_tree.built()) all_tree.erase(i);
    reflex_tree.erase(i);
    // A cut only ever makes its neighbours more convex (in a simple ring): once convex, a corner
    // can no longer block an ear.
    if (orient(at(p).prev, p, n) > 0.0) reflex_tree.erase(p);
    if (orient(p, n, at(n).next) > 0.0) reflex_tree.erase(n);
  }

  // Marks the ring's nodes alive, sets the step budget and, for a large ring, builds the tree of
  // its corners that are not convex.
  void start_clipping(std::int32_t start, std::size_t count) {
    alive.assign(nodes.size(), 0);
    std::vector<std::int32_t> reflex;
    double magnitude = 0.0;
    std::int32_t p = start;
    do {
      alive[static_cast<std::size_t>(p)] = 1;
      if (orient(at(p).prev, p, at(p).next) <= 0.0) reflex.push_back(p);
      magnitude = std::max({magnitude, std::abs(at(p).x), std::abs(at(p).y)});
      p = at(p).next;
    } while (p != start);
    thin_height = kThinEarFloatSteps * magnitude * std::numeric_limits<float>::epsilon();
    // A simple ring costs a few dozen steps a vertex; this leaves room for hard ones, not for
    // self-intersecting rings that defeat the trees and would cost n² steps.
    budget = (std::uint64_t{1} << 20) + 32 * std::uint64_t{count} * std::bit_width(count);
    if (count < kTreeFrom) return;
    use_trees = true;
    reflex_tree.build(nodes, reflex);
  }

  // The tree of every corner left, for the loose ear test (only degenerate rings need it).
  const NodeTree& all_corners(std::int32_t start) {
    if (!all_tree.built()) {
      std::vector<std::int32_t> ring;
      std::int32_t p = start;
      do {
        ring.push_back(p);
        p = at(p).next;
      } while (p != start);
      all_tree.build(nodes, ring);
    }
    return all_tree;
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

  bool is_ear(std::int32_t e, bool strict) {
    const std::int32_t a = at(e).prev, c = at(e).next;
    const Node &na = at(a), &nb = at(e), &nc = at(c);
    const double turn = orient(a, e, c);
    if (strict) {
      const double la = std::hypot(nb.x - na.x, nb.y - na.y), lc = std::hypot(nc.x - nb.x, nc.y - nb.y);
      if (!(turn > straight_sine * la * lc)) return false;
    } else if (!(turn > 0.0)) {
      return false;
    }
    const double x0 = std::min({na.x, nb.x, nc.x}), x1 = std::max({na.x, nb.x, nc.x});
    const double y0 = std::min({na.y, nb.y, nc.y}), y1 = std::max({na.y, nb.y, nc.y});
    const auto blocker = [&](std::int32_t p) {
      if (!alive[static_cast<std::size_t>(p)] || p == a || p == e || p == c) return false;
      const Node& np = at(p);
      if (np.x < x0 || np.x > x1 || np.y < y0 || np.y > y1) return false;
      return blocks(p, a, e, c, strict);
    };
    if (use_trees) {
      const Triangle2 t{na.x, na.y, nb.x, nb.y, nc.x, nc.y};
      return !(strict ? reflex_tree : all_corners(e)).any_near(t, steps, blocker);
    }
    for (std::int32_t p = at(c).next; p != a; p = at(p).next) {
      ++steps;
      if (blocker(p)) return false;
    }
    return true;
  }

  // No ear at all (self-touching or numerically flat input): cut the most convex corner. Returns
  // the corner after it.
  std::int32_t cut_most_convex(std::int32_t ear) {
    std::int32_t best = ear;
    double best_turn = -std::numeric_limits<double>::infinity();
    std::int32_t p = ear;
    do {
      ++steps;
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
    return after;
  }

  // Past the budget: every corner cut as it comes (still n + 2h − 2 triangles using every
  // boundary edge once, so a cap stays closed, but they may overlap).
  std::int32_t cut_rest(std::int32_t ear, std::size_t& count) {
    exhausted = true;
    while (count > 3) {
      const std::int32_t next = at(ear).next;
      if (at(ear).index != at(next).index) emit(at(ear).prev, ear, next);
      remove(ear);
      --count;
      ear = next;
    }
    return ear;
  }

  void clip(std::int32_t start, std::size_t count) {
    std::int32_t ear = start, stop = start;
    int pass = 0;
    while (count > 3) {
      if (steps > budget) {
        ear = cut_rest(ear, count);
        break;
      }
      const std::int32_t prev = at(ear).prev, next = at(ear).next;
      const bool copy = at(ear).index == at(next).index;  // two copies of one vertex in a row: no triangle
      if (copy || same_point(ear, next) || (pass == 0 && is_ear(ear, true)) || (pass == 1 && is_ear(ear, false))) {
        if (!copy) emit(prev, ear, next);
        remove(ear);
        --count;
        ear = stop = next;
        pass = 0;
        continue;
      }
      ++steps;
      ear = next;
      if (ear != stop) continue;
      if (pass < 2) {
        ++pass;
        continue;
      }
      ear = stop = cut_most_convex(ear);
      --count;
      pass = 0;
    }
    if (count == 3) emit(at(ear).prev, ear, at(ear).next);
  }

  // Large rings: the corners to test wait in a queue, oldest first. A cut re-queues its two
  // neighbours at the back (their older entries go stale), so each corner is tested once plus
  // twice per cut, and the cuts go round the ring (every other corner, then every other of the
  // rest, ...) instead of fanning from one corner. In a simple ring a cut changes no other
  // corner's ear status (a triangle holding a corner holds a reflex one), except where corners
  // lie on another's ear (collinear runs): when the queue runs dry every corner is tested again,
  // and when that finds no ear either, one ring walk finds a loose ear or the most convex corner.
  void clip_queued(std::int32_t start, std::size_t count) {
    // Corners to test, and ears too thin to cut while other ears remain (kThinEarFloatSteps).
    std::deque<std::pair<std::int32_t, std::uint32_t>> queue, thin;  // node, its stamp when queued
    std::vector<std::uint32_t> stamp(nodes.size(), 0);
    const auto requeue = [&](std::int32_t q) { queue.emplace_back(q, ++stamp[static_cast<std::size_t>(q)]); };
    std::int32_t p = start;
    do {
      queue.emplace_back(p, 0);
      p = at(p).next;
    } while (p != start);
    std::int32_t last = start;  // a corner still in the ring
    bool retested = false;      // every corner re-queued since the last cut
    while (count > 3) {
      if (steps > budget) {
        last = cut_rest(last, count);
        break;
      }
      if (queue.empty() && thin.empty()) {
        // Dry: a corner on the boundary of another's ear (collinear runs, touching rings) can
        // stop blocking it without being its neighbour. Test them all once more, as a walk would;
        // when that finds nothing either, force a cut.
        if (!retested) {
          for (p = at(last).next; p != last; p = at(p).next) requeue(p);
          requeue(last);
          retested = true;
          continue;
        }
        last = cut_without_strict_ear(last);
        --count;
        requeue(last);
        requeue(at(last).prev);
        retested = false;
        continue;
      }
      const bool from_thin = queue.empty();
      auto& from = from_thin ? thin : queue;
      const auto [e, queued] = from.front();
      from.pop_front();
      ++steps;
      if (!alive[static_cast<std::size_t>(e)] || queued != stamp[static_cast<std::size_t>(e)]) continue;
      const std::int32_t prev = at(e).prev, next = at(e).next;
      const bool copy = at(e).index == at(next).index;  // two copies of one vertex in a row: no triangle
      if (!copy && !same_point(e, next) && !is_ear(e, true)) continue;
      if (!copy && !from_thin && height(prev, e, next) < thin_height) {
        thin.emplace_back(e, queued);
        continue;
      }
      if (!copy) emit(prev, e, next);
      remove(e);
      --count;
      requeue(prev);
      requeue(next);
      last = next;
      retested = false;
    }
    if (count == 3) emit(at(last).prev, last, at(last).next);
  }

  // The triangle's height over its longest side.
  double height(std::int32_t a, std::int32_t b, std::int32_t c) const {
    const auto d2 = [this](std::int32_t p, std::int32_t q) {
      const double dx = at(q).x - at(p).x, dy = at(q).y - at(p).y;
      return dx * dx + dy * dy;
    };
    const double longest = std::sqrt(std::max({d2(a, b), d2(b, c), d2(c, a)}));
    return longest > 0.0 ? orient(a, b, c) / longest : 0.0;
  }

  // No strict ear left: the first loose ear from `from` on, else the most convex corner, is cut.
  // Returns the corner after it.
  std::int32_t cut_without_strict_ear(std::int32_t from) {
    std::int32_t p = from;
    do {
      ++steps;
      if (is_ear(p, false)) {
        const std::int32_t after = at(p).next;
        emit(at(p).prev, p, after);
        remove(p);
        return after;
      }
      p = at(p).next;
    } while (p != from);
    return cut_most_convex(from);
  }
};

}  // namespace

std::vector<std::array<std::int32_t, 3>> triangulate_polygon_with_holes(const Polygon2& outer,
                                                                        const std::vector<Polygon2>& holes,
                                                                        double straight_sine, TriangulationWork* work) {
  if (outer.size() < 3) return {};
  Triangulator tri;
  tri.straight_sine = straight_sine;
  std::size_t total = outer.size();
  for (const auto& h : holes) total += h.size();
  tri.nodes.reserve(total + 2 * holes.size());
  const std::int32_t outer_node = tri.link_ring(outer, 0, true);
  const std::size_t count = outer.size() + tri.bridge_holes(outer_node, holes, static_cast<std::int32_t>(outer.size()));
  tri.out.reserve(count - 2);
  tri.start_clipping(outer_node, count);
  if (tri.use_trees)
    tri.clip_queued(outer_node, count);
  else
    tri.clip(outer_node, count);
  if (work != nullptr) *work = TriangulationWork{tri.steps, tri.exhausted};
  return std::move(tri.out);
}

}  // namespace lamina::geometry_detail
