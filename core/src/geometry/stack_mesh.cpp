// The stack as cut: per layer and outline group (an outer outline with its holes) a closed shell.
// Rings of edge points at a set of heights (the layer's faces, its sub-slices and the midpoints
// between them), walls between consecutive rings, caps at the faces triangulated with their
// holes on exactly the ring vertices, so every shell is a closed 2-manifold by construction.
//
// Tangled rings. Where the cuts overshoot an outline (near a pole, a small hole, a sharp inward
// corner), the ring of edge points at a height can cross itself, cross another ring of its group,
// run backwards, or turn inside out. The shell is then built from a clamped ring instead: starting
// from a height where the group's rings are clean (the one nearest the layer's middle; the base
// outline when none is), the heights are walked up and down, and every point of an offending
// edge is pulled back to where it was on the ring just walked (repeated until the ring is clean;
// the whole previous ring when that does not converge). The wall there becomes vertical from the
// last clean height: the mesh keeps slightly more material than the cuts do at such spots (the
// sections used for the deviation volume, layer_section, drop the tangled parts instead).
#include "lamina/core/stack_mesh.hpp"

#include "geometry/polygon_triangulation.hpp"
#include "geometry/stack_geometry.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>

namespace lamina {
namespace geometry_detail {
namespace {

using Rings = std::vector<Polygon2>;  // one group at one height: outer first, then its holes
using Marks = std::vector<std::vector<char>>;

double cross(const Eigen::Vector2d& a, const Eigen::Vector2d& b) { return a.x() * b.y() - a.y() * b.x(); }
double orient(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c) {
  return cross(b - a, c - a);
}

bool on_segment(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& p) {
  return std::min(a.x(), b.x()) <= p.x() && p.x() <= std::max(a.x(), b.x()) && std::min(a.y(), b.y()) <= p.y() &&
         p.y() <= std::max(a.y(), b.y());
}

// Closed segments ab and cd share a point.
bool segments_touch(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c,
                    const Eigen::Vector2d& d) {
  const double o1 = orient(a, b, c), o2 = orient(a, b, d), o3 = orient(c, d, a), o4 = orient(c, d, b);
  if (((o1 > 0 && o2 < 0) || (o1 < 0 && o2 > 0)) && ((o3 > 0 && o4 < 0) || (o3 < 0 && o4 > 0))) return true;
  return (o1 == 0 && on_segment(a, b, c)) || (o2 == 0 && on_segment(a, b, d)) || (o3 == 0 && on_segment(c, d, a)) ||
         (o4 == 0 && on_segment(c, d, b));
}

// A ring with runs of coincident points merged (zero-length edges are not crossings).
struct CompactRing {
  std::vector<Eigen::Vector2d> points;
  std::vector<std::size_t> first, last;  // original indices of each compact point's run
  std::vector<std::size_t> of;           // compact point of each original index
};

bool compact(const Polygon2& ring, CompactRing& c) {
  const std::size_t n = ring.size();
  c = CompactRing{};
  c.of.assign(n, 0);
  std::size_t i0 = n;
  for (std::size_t i = 0; i < n; ++i)
    if (ring[i] != ring[(i + n - 1) % n]) {
      i0 = i;
      break;
    }
  if (i0 == n) return false;
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t i = (i0 + k) % n;
    if (k == 0 || ring[i] != c.points.back()) {
      c.points.push_back(ring[i]);
      c.first.push_back(i);
      c.last.push_back(i);
    } else {
      c.last.back() = i;
    }
    c.of[i] = c.points.size() - 1;
  }
  return c.points.size() >= 3;
}

// Winding number of p about a ring.
int winding(const std::vector<Eigen::Vector2d>& ring, const Eigen::Vector2d& p) {
  int w = 0;
  const std::size_t n = ring.size();
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector2d& a = ring[i];
    const Eigen::Vector2d& b = ring[(i + 1) % n];
    if (a.y() <= p.y()) {
      if (b.y() > p.y() && orient(a, b, p) > 0) ++w;
    } else if (b.y() <= p.y() && orient(a, b, p) < 0) {
      --w;
    }
  }
  return w;
}

// The edges of a group at one height, and what is wrong with them (find_tangles below).
struct TangleFinder {
  struct Seg {
    std::uint32_t ring, index;
    Eigen::Vector2d a, b;
  };
  TangleFinder(const Rings& r, const Rings& b, Marks& m) : rings(r), base(b), marks(m) {}

  const Rings& rings;
  const Rings& base;
  Marks& marks;
  std::vector<CompactRing> comp;
  std::vector<char> whole;  // ring marked entirely
  std::vector<Seg> segs;
  Eigen::Vector2d lo{std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity()};
  Eigen::Vector2d hi{-std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity()};
  bool any = false;

  void mark_compact(std::size_t r, std::size_t j) {
    const CompactRing& c = comp[r];
    const std::size_t n = rings[r].size();
    for (std::size_t i = c.first[j];; i = (i + 1) % n) {
      marks[r][i] = 1;
      if (i == c.last[j]) break;
    }
    any = true;
  }

  // Rings that cannot be compacted, or wound the wrong way, are marked whole.
  void compact_rings() {
    const std::size_t nr = rings.size();
    marks.assign(nr, {});
    comp.resize(nr);
    whole.assign(nr, 0);
    for (std::size_t r = 0; r < nr; ++r) {
      marks[r].assign(rings[r].size(), 0);
      if (!compact(rings[r], comp[r])) {
        whole[r] = 1;
        continue;
      }
      const double area = signed_area_mm2(comp[r].points);
      if (!(r == 0 ? area > 0.0 : area < 0.0)) whole[r] = 1;
    }
  }

  // The segments of the rings not marked whole; an edge running against its base edge (the
  // original edge between the two runs) is marked on the way.
  void collect_segments() {
    for (std::size_t r = 0; r < rings.size(); ++r) {
      if (whole[r]) continue;
      const CompactRing& c = comp[r];
      const std::size_t m = c.points.size();
      for (std::size_t j = 0; j < m; ++j) {
        const std::size_t k = (j + 1) % m;
        const Eigen::Vector2d be = base[r][c.first[k]] - base[r][c.last[j]];
        if (be.squaredNorm() > 1e-24 && (c.points[k] - c.points[j]).dot(be) < 0.0) {
          mark_compact(r, j);
          mark_compact(r, k);
        }
        segs.push_back({static_cast<std::uint32_t>(r), static_cast<std::uint32_t>(j), c.points[j], c.points[k]});
        lo = lo.cwiseMin(c.points[j]);
        hi = hi.cwiseMax(c.points[j]);
      }
    }
  }

  bool offending(const Seg& s, const Seg& t) const {
    const std::size_t m = comp[s.ring].points.size();
    if (s.ring == t.ring && (s.index + 1) % m == t.index)  // consecutive: only a fold back onto itself
      return orient(s.a, s.b, t.b) == 0.0 && (s.b - s.a).dot(t.b - t.a) < 0.0;
    if (s.ring == t.ring && (t.index + 1) % m == s.index)
      return orient(t.a, t.b, s.b) == 0.0 && (t.b - t.a).dot(s.b - s.a) < 0.0;
    return segments_touch(s.a, s.b, t.a, t.b);
  }

  void mark_pair(const Seg& s, const Seg& t) {
    for (const Seg* e : {&s, &t}) {
      const std::size_t mm = comp[e->ring].points.size();
      mark_compact(e->ring, e->index);
      mark_compact(e->ring, (e->index + 1) % mm);
    }
  }

  // Crossings, through a uniform grid of the segments' boxes; a pair is tested in the cell that
  // holds the low corner of the overlap of their boxes.
  void mark_crossings() {
    if (segs.empty()) return;
    const Eigen::Vector2d size = (hi - lo).cwiseMax(1e-9);
    const int g = std::clamp(static_cast<int>(std::sqrt(static_cast<double>(segs.size()))), 1, 1024);
    const double cw = std::max(size.x(), size.y()) / g;
    const int gx = std::clamp(static_cast<int>(std::ceil(size.x() / cw)), 1, 1024);
    const int gy = std::clamp(static_cast<int>(std::ceil(size.y() / cw)), 1, 1024);
    auto cell = [&](double v, double origin, int cells) {
      return std::clamp(static_cast<int>(std::floor((v - origin) / cw)), 0, cells - 1);
    };
    std::vector<std::uint32_t> begin(static_cast<std::size_t>(gx) * gy + 1, 0);
    auto for_cells = [&](const Seg& s, auto&& f) {
      const int x0 = cell(std::min(s.a.x(), s.b.x()), lo.x(), gx), x1 = cell(std::max(s.a.x(), s.b.x()), lo.x(), gx);
      const int y0 = cell(std::min(s.a.y(), s.b.y()), lo.y(), gy), y1 = cell(std::max(s.a.y(), s.b.y()), lo.y(), gy);
      for (int y = y0; y <= y1; ++y)
        for (int x = x0; x <= x1; ++x) f(static_cast<std::size_t>(y) * gx + x);
    };
    for (const auto& s : segs) for_cells(s, [&](std::size_t c) { ++begin[c + 1]; });
    for (std::size_t c = 0; c + 1 < begin.size(); ++c) begin[c + 1] += begin[c];
    std::vector<std::uint32_t> items(begin.back());
    std::vector<std::uint32_t> fill(begin.begin(), begin.end() - 1);
    for (std::uint32_t i = 0; i < segs.size(); ++i) for_cells(segs[i], [&](std::size_t c) { items[fill[c]++] = i; });

    for (std::size_t c = 0; c + 1 < begin.size(); ++c) {
      const int cx = static_cast<int>(c % static_cast<std::size_t>(gx)), cy = static_cast<int>(c / static_cast<std::size_t>(gx));
      for (std::uint32_t p = begin[c]; p < begin[c + 1]; ++p) {
        const Seg& s = segs[items[p]];
        for (std::uint32_t q = p + 1; q < begin[c + 1]; ++q) {
          const Seg& t = segs[items[q]];
          const double ox = std::max(std::min(s.a.x(), s.b.x()), std::min(t.a.x(), t.b.x()));
          const double oy = std::max(std::min(s.a.y(), s.b.y()), std::min(t.a.y(), t.b.y()));
          if (ox > std::min(std::max(s.a.x(), s.b.x()), std::max(t.a.x(), t.b.x())) ||
              oy > std::min(std::max(s.a.y(), s.b.y()), std::max(t.a.y(), t.b.y())))
            continue;  // boxes apart
          if (cell(ox, lo.x(), gx) != cx || cell(oy, lo.y(), gy) != cy) continue;
          if (offending(s, t)) mark_pair(s, t);
        }
      }
    }
  }

  // Holes inside the outer and outside each other (with no crossing, one point tells).
  void check_holes() {
    if (whole[0]) return;
    const std::size_t nr = rings.size();
    for (std::size_t r = 1; r < nr; ++r) {
      if (whole[r]) continue;
      const Eigen::Vector2d& p = comp[r].points[0];
      bool bad = winding(comp[0].points, p) == 0;
      for (std::size_t q = 1; q < nr && !bad; ++q)
        if (q != r && !whole[q] && winding(comp[q].points, p) != 0) bad = true;
      if (bad) whole[r] = 1;
    }
  }

  void mark_wholes() {
    for (std::size_t r = 0; r < rings.size(); ++r)
      if (whole[r]) {
        std::fill(marks[r].begin(), marks[r].end(), 1);
        any = true;
      }
  }
};

// Marks the points of every offending edge of a group at one height; false when it is clean
// (no crossing or touching edges, no edge running against its base edge, outer counter-clockwise,
// holes clockwise and inside the outer, outside each other).
bool find_tangles(const Rings& rings, const Rings& base, Marks& marks) {
  TangleFinder f{rings, base, marks};
  f.compact_rings();
  f.collect_segments();
  f.mark_crossings();
  f.check_holes();
  f.mark_wholes();
  return f.any;
}

// The raw ring set pulled back onto `prev` where it is tangled (see the file comment).
Rings clamp_rings(Rings cur, const Rings& prev, const Rings& base) {
  Marks marks;
  for (int iter = 0; iter < 64; ++iter) {
    if (!find_tangles(cur, base, marks)) return cur;
    bool changed = false;
    for (std::size_t r = 0; r < cur.size(); ++r)
      for (std::size_t i = 0; i < cur[r].size(); ++i)
        if (marks[r][i] && cur[r][i] != prev[r][i]) {
          cur[r][i] = prev[r][i];
          changed = true;
        }
    if (!changed) break;
  }
  return prev;
}

// Heights of the rings of a layer: its faces, the sub-slices between them (the 1 µm nudge off the
// faces snapped away), and the midpoints.
std::vector<double> ring_heights(const LayerPlan& layer) {
  const double zb = layer.z_bottom_mm, zt = layer.z_top_mm();
  const double snap = std::min(5e-3, 0.25 * layer.thickness_mm);
  std::vector<double> hs{zb, zt};
  for (double z : layer.sub_slice_z_mm)
    if (std::isfinite(z) && z > zb + snap && z < zt - snap) hs.push_back(z);
  std::sort(hs.begin(), hs.end());
  hs.erase(std::unique(hs.begin(), hs.end(), [](double a, double b) { return b - a < 1e-9; }), hs.end());
  std::vector<double> out;
  out.reserve(2 * hs.size());
  for (std::size_t i = 0; i < hs.size(); ++i) {
    if (i > 0) out.push_back(0.5 * (hs[i - 1] + hs[i]));
    out.push_back(hs[i]);
  }
  return out;
}

// The stations of an outline in the order that makes its base ring wind the way it should
// (outers counter-clockwise, holes clockwise).
std::vector<std::size_t> station_order(const LayerOutline& o, bool hole) {
  std::vector<std::size_t> order(o.stations.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  const double area = signed_area_mm2(base_ring(o));
  if (hole ? area > 0.0 : area < 0.0) std::reverse(order.begin(), order.end());
  return order;
}

// The heights whose rings the wall needs (issue 17, item 8: a 2,174-triangle model's stack.stl
// was 1.2 M triangles, every wall in 0.25 mm rows even where it was one straight cut). A ring
// that lies within kRuledEps of the straight lines between the kept rings below and above it
// adds nothing the ruled wall between those does not have, and goes: a single-cut wall keeps its
// two faces, a curved one a ring where its lines kink.
constexpr double kRuledEps = 1e-4;

bool between(const Rings& lo, const Rings& mid, const Rings& hi, double f) {
  for (std::size_t r = 0; r < mid.size(); ++r)
    for (std::size_t i = 0; i < mid[r].size(); ++i)
      if ((mid[r][i] - (lo[r][i] + f * (hi[r][i] - lo[r][i]))).squaredNorm() > kRuledEps * kRuledEps) return false;
  return true;
}

std::vector<std::size_t> needed_heights(const std::vector<Rings>& rings, const std::vector<double>& heights) {
  std::vector<std::size_t> kept{0};
  const std::size_t nk = rings.size();
  for (std::size_t next = 2; next < nk; ++next) {
    // Can the wall go straight from the last kept ring to `next`, past every ring between?
    const std::size_t from = kept.back();
    bool straight = true;
    for (std::size_t k = from + 1; k < next && straight; ++k)
      straight = between(rings[from], rings[k], rings[next], (heights[k] - heights[from]) / (heights[next] - heights[from]));
    if (!straight) kept.push_back(next - 1);
  }
  if (nk > 1) kept.push_back(nk - 1);
  return kept;
}

// The rings (and their heights) reduced to those needed_heights keeps.
void keep_needed_rings(std::vector<Rings>& rings, std::vector<double>& heights) {
  std::vector<Rings> kept_rings;
  std::vector<double> kept_heights;
  for (std::size_t k : needed_heights(rings, heights)) {
    kept_rings.push_back(std::move(rings[k]));
    kept_heights.push_back(heights[k]);
  }
  rings = std::move(kept_rings);
  heights = std::move(kept_heights);
}

// Every height's rings pulled back where they tangle: from the clean height nearest the middle
// (or, with none, the middle one clamped onto the base) outwards, each onto its neighbour.
std::vector<Rings> untangled(const std::vector<Rings>& raw, const Rings& base) {
  const std::size_t nk = raw.size();
  std::vector<Rings> clean(nk);
  Marks marks;
  std::size_t seed = nk;
  const double middle = 0.5 * static_cast<double>(nk - 1);
  for (std::size_t k = 0; k < nk; ++k)
    if (!find_tangles(raw[k], base, marks) &&
        (seed == nk || std::abs(static_cast<double>(k) - middle) < std::abs(static_cast<double>(seed) - middle)))
      seed = k;
  if (seed == nk) {
    seed = nk / 2;
    clean[seed] = clamp_rings(raw[seed], base, base);
  } else {
    clean[seed] = raw[seed];
  }
  for (std::size_t k = seed + 1; k < nk; ++k) clean[k] = clamp_rings(raw[k], clean[k - 1], base);
  for (std::size_t k = seed; k-- > 0;) clean[k] = clamp_rings(raw[k], clean[k + 1], base);
  return clean;
}

// Vertices, walls and caps of one group: its rings at each height, `sizes` points each.
void add_group_mesh(const std::vector<Rings>& clean, const std::vector<double>& heights,
                    const std::vector<std::size_t>& sizes, StackShells& shells) {
  const std::size_t nk = heights.size(), nr = sizes.size();
  std::size_t per_height = 0;
  std::vector<std::size_t> ring_start(nr);
  for (std::size_t r = 0; r < nr; ++r) {
    ring_start[r] = per_height;
    per_height += sizes[r];
  }
  // Vertices: height by height, ring by ring.
  const std::size_t first = shells.vertices.size();
  shells.vertices.reserve(first + nk * per_height);
  for (std::size_t k = 0; k < nk; ++k)
    for (std::size_t r = 0; r < nr; ++r)
      for (const auto& p : clean[k][r]) shells.vertices.emplace_back(p.x(), p.y(), heights[k]);
  auto v = [&](std::size_t k, std::size_t r, std::size_t i) {
    return static_cast<std::int32_t>(first + k * per_height + ring_start[r] + i % sizes[r]);
  };
  // Walls: outer rings counter-clockwise and holes clockwise seen from above, so (along the ring)
  // × up points out of the material in both.
  for (std::size_t r = 0; r < nr; ++r)
    for (std::size_t k = 0; k + 1 < nk; ++k)
      for (std::size_t i = 0; i < sizes[r]; ++i) {
        const std::int32_t a = v(k, r, i), b = v(k, r, i + 1), c = v(k + 1, r, i + 1), d = v(k + 1, r, i);
        shells.faces.push_back({a, b, c});
        shells.faces.push_back({a, c, d});
      }
  // Caps, on exactly the ring vertices (the triangulation numbers outer then holes, as above).
  for (const std::size_t k : {nk - 1, std::size_t{0}}) {
    const Rings& rings = clean[k];
    const std::vector<Polygon2> holes(rings.begin() + 1, rings.end());
    const auto tris = triangulate_polygon_with_holes(rings[0], holes);
    const auto offset = static_cast<std::int32_t>(first + k * per_height);
    for (const auto& t : tris) {
      if (k + 1 == nk)
        shells.faces.push_back({offset + t[0], offset + t[1], offset + t[2]});
      else
        shells.faces.push_back({offset + t[0], offset + t[2], offset + t[1]});
    }
  }
  ++shells.shells;
}

void build_group(const LayerPlan& layer, const OutlineGroup& group, const std::vector<double>& all_heights,
                 StackShells& shells) {
  std::vector<const LayerOutline*> outlines{&layer.outlines[static_cast<std::size_t>(group.outer)]};
  for (int h : group.holes) outlines.push_back(&layer.outlines[static_cast<std::size_t>(h)]);
  const std::size_t nr = outlines.size();
  std::vector<std::vector<std::size_t>> order(nr);
  Rings base(nr);
  std::vector<std::size_t> sizes(nr);
  for (std::size_t r = 0; r < nr; ++r) {
    order[r] = station_order(*outlines[r], r > 0);
    for (std::size_t i : order[r]) base[r].push_back(outlines[r]->stations[i].base_mm);
    sizes[r] = base[r].size();
  }
  auto raw_rings = [&](double z) {
    const double t = layer_t(layer, z);
    Rings rings(nr);
    for (std::size_t r = 0; r < nr; ++r) {
      rings[r].reserve(order[r].size());
      for (std::size_t i : order[r]) {
        const CutStation& st = outlines[r]->stations[i];
        rings[r].push_back(st.base_mm + station_offset(*outlines[r], i, t) * st.normal);
      }
    }
    return rings;
  };
  std::vector<double> heights = all_heights;
  std::vector<Rings> raw(heights.size());
  for (std::size_t k = 0; k < heights.size(); ++k) raw[k] = raw_rings(heights[k]);
  std::vector<Rings> clean = untangled(raw, base);
  keep_needed_rings(clean, heights);
  add_group_mesh(clean, heights, sizes, shells);
}

}  // namespace

// Layer by layer on several threads, joined in layer order: the same shells as one after the
// other (the deviation and stack.stl of the 1M sphere build 680k triangles each).
StackShells build_stack_shells(const BevelPlan& plan) {
  std::vector<StackShells> per_layer(plan.layers.size());
  tbb::parallel_for(std::size_t{0}, plan.layers.size(), [&](std::size_t l) {
    const LayerPlan& layer = plan.layers[l];
    if (!(layer.thickness_mm > 0.0) || !std::isfinite(layer.thickness_mm) || !std::isfinite(layer.z_bottom_mm))
      return;
    const auto heights = ring_heights(layer);
    for (const auto& group : outline_groups(layer)) build_group(layer, group, heights, per_layer[l]);
  });
  StackShells shells;
  std::size_t vertices = 0, faces = 0;
  for (const StackShells& one : per_layer) vertices += one.vertices.size(), faces += one.faces.size();
  shells.vertices.reserve(vertices);
  shells.faces.reserve(faces);
  for (const StackShells& one : per_layer) {
    const auto offset = static_cast<std::int32_t>(shells.vertices.size());
    shells.vertices.insert(shells.vertices.end(), one.vertices.begin(), one.vertices.end());
    for (const auto& f : one.faces) shells.faces.push_back({f[0] + offset, f[1] + offset, f[2] + offset});
    shells.shells += one.shells;
  }
  return shells;
}

}  // namespace detail

TriangleSoup stack_mesh(const BevelPlan& plan) {
  const geometry_detail::StackShells shells = geometry_detail::build_stack_shells(plan);
  TriangleSoup soup;
  soup.format = "stack";
  soup.corners.reserve(3 * shells.faces.size());
  for (const auto& f : shells.faces)
    for (const std::int32_t v : f) soup.corners.push_back(shells.vertices[static_cast<std::size_t>(v)].cast<float>());
  return soup;
}

}  // namespace lamina
