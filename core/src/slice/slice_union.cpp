// Overlapping shells (CAD bodies exported as one file without a boolean union) must slice to the
// union of the solids. The loops are split where loops meet (crossing, touching, or running along
// each other where bodies touch face to face); a piece stays on the boundary iff the total winding
// number just to its right (its outside) is 0 — its left is then inside. Of coincident pieces
// facing the same way one is kept; coincident pieces facing each other (an internal wall) go.
// Surviving pieces keep their facet, so the contour vectors still know the facet normal and surface they came from.
#include "slice/slice_internal.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <set>

namespace lamina::slice_detail {
namespace {

struct Seg {
  Eigen::Vector2d a, b;
  std::size_t loop, index;
  double xmin, xmax, ymin, ymax;
};

double orient(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c) {
  return (b.x() - a.x()) * (c.y() - a.y()) - (b.y() - a.y()) * (c.x() - a.x());
}

std::vector<Seg> segments_of(const std::vector<Loop>& loops) {
  std::vector<Seg> segs;
  for (std::size_t l = 0; l < loops.size(); ++l) {
    const auto& pts = loops[l].points;
    for (std::size_t i = 0; i < pts.size(); ++i) {
      const Eigen::Vector2d& a = pts[i];
      const Eigen::Vector2d& b = pts[(i + 1) % pts.size()];
      segs.push_back({a, b, l, i, std::min(a.x(), b.x()), std::max(a.x(), b.x()), std::min(a.y(), b.y()),
                      std::max(a.y(), b.y())});
    }
  }
  std::sort(segs.begin(), segs.end(), [](const Seg& p, const Seg& q) { return p.xmin < q.xmin; });
  return segs;
}

// Sweep in x over segments sorted by xmin; `visit(o, cur, hit)` is called for every pair of
// segments from different loops that meet (crossing, or touching at an end point; collinear
// overlaps are left alone) and for which `pair_ok(loop_a, loop_b)` holds. It returns false to stop.
struct Hit {
  Eigen::Vector2d point;  // exact: an end point when one lies on the other segment
  double t_o, t_cur;      // parameters along o and cur (0 or 1 at their own end points)
};

// Parameter of p along a → b (p on that line).
double param(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& p) {
  const Eigen::Vector2d d = b - a;
  return (p - a).dot(d) / d.squaredNorm();
}

template <class PairOk, class Visit>
void for_each_intersection(const std::vector<Seg>& segs, PairOk pair_ok, Visit visit) {
  std::vector<std::size_t> active;
  for (std::size_t s = 0; s < segs.size(); ++s) {
    const Seg& cur = segs[s];
    std::size_t w = 0;
    bool stop = false;
    for (std::size_t k = 0; k < active.size(); ++k) {
      const Seg& o = segs[active[k]];
      if (o.xmax < cur.xmin) continue;  // left behind by the sweep
      active[w++] = active[k];
      if (stop || o.loop == cur.loop || o.ymax < cur.ymin || o.ymin > cur.ymax || !pair_ok(o.loop, cur.loop)) continue;
      const double o1 = orient(cur.a, cur.b, o.a), o2 = orient(cur.a, cur.b, o.b);
      const double o3 = orient(o.a, o.b, cur.a), o4 = orient(o.a, o.b, cur.b);
      if ((o1 > 0 && o2 > 0) || (o1 < 0 && o2 < 0) || (o3 > 0 && o4 > 0) || (o3 < 0 && o4 < 0)) continue;
      if (o1 == 0 && o2 == 0) {
        // Collinear (walls of bodies touching face to face): every end point of one lying inside
        // the other is a meeting point, so the overlap becomes whole, coincident pieces.
        for (const Eigen::Vector2d* p : {&o.a, &o.b}) {
          const double t = param(cur.a, cur.b, *p);
          if (t > 0 && t < 1 && !stop) stop = !visit(o, cur, Hit{*p, p == &o.a ? 0.0 : 1.0, t});
        }
        for (const Eigen::Vector2d* p : {&cur.a, &cur.b}) {
          const double t = param(o.a, o.b, *p);
          if (t > 0 && t < 1 && !stop) stop = !visit(o, cur, Hit{*p, t, p == &cur.a ? 0.0 : 1.0});
        }
        continue;
      }
      Hit h;
      h.t_o = o1 / (o1 - o2);
      h.t_cur = o3 / (o3 - o4);
      if (o1 == 0) h.point = o.a, h.t_o = 0;
      else if (o2 == 0) h.point = o.b, h.t_o = 1;
      else if (o3 == 0) h.point = cur.a, h.t_cur = 0;
      else if (o4 == 0) h.point = cur.b, h.t_cur = 1;
      else h.point = o.a + h.t_o * (o.b - o.a);
      if (h.point == cur.a) h.t_cur = 0;
      if (h.point == cur.b) h.t_cur = 1;
      if (h.point == o.a) h.t_o = 0;
      if (h.point == o.b) h.t_o = 1;
      stop = !visit(o, cur, h);
    }
    active.resize(w);
    if (stop) return;
    active.push_back(s);
  }
}

}  // namespace

bool needs_union(const std::vector<Loop>& loops, const std::vector<int>& loop_shell) {
  for (const Loop& l : loops)
    if ((l.depth % 2 == 0) != (l.area_mm2 > 0.0)) return true;
  bool several_shells = false;
  for (std::size_t i = 1; i < loop_shell.size(); ++i) several_shells |= loop_shell[i] != loop_shell[0];
  if (!several_shells) return false;
  bool meet = false;
  for_each_intersection(
      segments_of(loops), [&](std::size_t a, std::size_t b) { return loop_shell[a] != loop_shell[b]; },
      [&](const Seg&, const Seg&, const Hit&) {
        meet = true;
        return false;
      });
  return meet;
}

namespace {

using Splits = std::vector<std::vector<std::vector<std::pair<double, Eigen::Vector2d>>>>;
using Junctions = std::set<std::pair<double, double>>;

struct Piece {
  Eigen::Vector2d a, b;
  std::int32_t facet;
  std::size_t loop;
};

// Split points per (loop, vector): parameter along the vector and the shared point; and every
// meeting point, split or not.
void find_splits(const std::vector<Loop>& loops, Splits& splits, Junctions& junctions) {
  splits.assign(loops.size(), {});
  for (std::size_t l = 0; l < loops.size(); ++l) splits[l].resize(loops[l].points.size());
  for_each_intersection(
      segments_of(loops), [](std::size_t, std::size_t) { return true; },
      [&](const Seg& o, const Seg& cur, const Hit& h) {
        // One point for both pieces, so chaining by exact equality works.
        junctions.emplace(h.point.x(), h.point.y());
        if (h.t_cur > 0 && h.t_cur < 1) splits[cur.loop][cur.index].emplace_back(h.t_cur, h.point);
        if (h.t_o > 0 && h.t_o < 1) splits[o.loop][o.index].emplace_back(h.t_o, h.point);
        return true;
      });
}

// Loop l cut at its split points into pieces.
std::vector<Piece> pieces_of(const Loop& loop, std::size_t l, std::vector<std::vector<std::pair<double, Eigen::Vector2d>>>& sp_of) {
  std::vector<Piece> pieces;
  const std::size_t n = loop.points.size();
  for (std::size_t i = 0; i < n; ++i) {
    auto& sp = sp_of[i];
    std::sort(sp.begin(), sp.end(), [](const auto& p, const auto& q) { return p.first < q.first; });
    Eigen::Vector2d from = loop.points[i];
    for (const auto& [t, p] : sp) {
      if (p == from) continue;
      pieces.push_back({from, p, loop.facets[i], l});
      from = p;
    }
    if (from != loop.points[(i + 1) % n]) pieces.push_back({from, loop.points[(i + 1) % n], loop.facets[i], l});
  }
  return pieces;
}

// Whether a run of pieces [b, e) is on the union's boundary: just right of its longest piece
// (the least likely to touch another loop; its outside) the total winding is 0. Off the piece
// itself, so a coincident wall of another body is on a definite side.
bool run_on_boundary(const std::vector<Piece>& pieces, std::size_t b, std::size_t e, const std::vector<Loop>& loops) {
  std::size_t probe = b;
  for (std::size_t k = b; k < e; ++k)
    if ((pieces[k].b - pieces[k].a).squaredNorm() > (pieces[probe].b - pieces[probe].a).squaredNorm()) probe = k;
  const Eigen::Vector2d d = pieces[probe].b - pieces[probe].a;
  const Eigen::Vector2d mid = 0.5 * (pieces[probe].a + pieces[probe].b);
  const double step = std::max(1e-9 * d.norm(), 1e-12 * (1.0 + mid.cwiseAbs().maxCoeff()));  // well above an ulp
  const Eigen::Vector2d right = mid + step * Eigen::Vector2d(d.y(), -d.x()).normalized();
  int w = 0;
  for (const Loop& o : loops) w += winding_number(o, right);
  return w == 0;
}

// The pieces on the union's boundary: runs between meeting points, one winding evaluation per
// run. Coincident walls facing the same way (two bodies flush on one side) survive twice: one kept.
std::vector<Piece> boundary_pieces(const std::vector<Loop>& loops, Splits& splits, const Junctions& junctions) {
  std::vector<Piece> kept;
  for (std::size_t l = 0; l < loops.size(); ++l) {
    const std::vector<Piece> pieces = pieces_of(loops[l], l, splits[l]);
    std::vector<std::size_t> run_start{0};
    for (std::size_t k = 1; k < pieces.size(); ++k)
      if (junctions.count({pieces[k].a.x(), pieces[k].a.y()})) run_start.push_back(k);
    run_start.push_back(pieces.size());
    for (std::size_t r = 0; r + 1 < run_start.size(); ++r) {
      if (run_start[r] == run_start[r + 1]) continue;
      if (run_on_boundary(pieces, run_start[r], run_start[r + 1], loops))
        for (std::size_t k = run_start[r]; k < run_start[r + 1]; ++k) kept.push_back(pieces[k]);
    }
  }
  std::set<std::array<double, 4>> seen;
  std::vector<Piece> unique;
  for (const Piece& p : kept)
    if (seen.insert({p.a.x(), p.a.y(), p.b.x(), p.b.y()}).second) unique.push_back(p);
  return unique;
}

// The kept pieces chained by exact end-point equality into closed loops.
std::vector<Loop> chain_pieces(const std::vector<Piece>& kept) {
  auto key = [](const Eigen::Vector2d& p) { return std::pair<double, double>(p.x(), p.y()); };
  std::multimap<std::pair<double, double>, std::size_t> by_start;
  for (std::size_t i = 0; i < kept.size(); ++i) by_start.emplace(key(kept[i].a), i);
  std::vector<char> used(kept.size(), 0);
  std::vector<Loop> out;
  for (std::size_t first = 0; first < kept.size(); ++first) {
    if (used[first]) continue;
    Loop loop;
    std::size_t cur = first;
    bool closed = false;
    for (;;) {
      used[cur] = 1;
      loop.points.push_back(kept[cur].a);
      loop.facets.push_back(kept[cur].facet);
      if (kept[cur].b == kept[first].a) {
        closed = true;
        break;
      }
      auto [lo, hi] = by_start.equal_range(key(kept[cur].b));
      // Where loops only touch, several pieces start here: stay on the same loop.
      std::size_t nxt = kept.size();
      for (auto it = lo; it != hi; ++it)
        if (!used[it->second] && (nxt == kept.size() || kept[it->second].loop == kept[cur].loop)) nxt = it->second;
      if (nxt == kept.size()) break;
      cur = nxt;
    }
    if (closed && loop.points.size() >= 3) out.push_back(std::move(loop));
  }
  return out;
}

}  // namespace

std::vector<Loop> union_of_loops(const std::vector<Loop>& loops) {
  Splits splits;
  Junctions junctions;
  find_splits(loops, splits, junctions);
  return chain_pieces(boundary_pieces(loops, splits, junctions));
}

}  // namespace lamina::slice_detail
