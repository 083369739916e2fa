// Plane ∩ mesh by topology: every facet crossing the plane gives one segment from the mesh edge
// where its winding goes down through the plane to the edge where it comes back up; segments are
// chained through those edges, so no distance tolerance is ever needed. A vertex exactly on the
// plane counts as above it (one consistent rule, "simulation of simplicity"): a facet crosses iff
// it has a vertex strictly below and one on or above, horizontal facets never cross, and the
// points on an edge ending at an on-plane vertex are that vertex, bit for bit.
#include "lamina/core/slice.hpp"
#include "lamina/core/surface_normal.hpp"

#include "slice/slice_internal.hpp"

#include <fmt/format.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <functional>
#include <cmath>
#include <numeric>

namespace lamina {
namespace {

struct Segment {
  Eigen::Vector2d start;    // the crossing point on start_edge
  std::int32_t start_edge;  // the facet's winding goes from above to below the plane here
  std::int32_t end_edge;    // ... and from below to above here
  std::int32_t face;
};

// Small open-addressing map from mesh edge to the first segment starting (or ending) there; a
// slice has a few thousand segments, so this stays in cache where a table over all edges would not.
class EdgeMap {
 public:
  void reset(std::size_t n) {
    std::size_t cap = 16;
    while (cap < 2 * n) cap <<= 1;
    keys_.assign(cap, -1);
    vals_.resize(cap);
    mask_ = cap - 1;
  }
  // Returns the slot's value, inserting `v` when the key is new (then `inserted` is true).
  std::int32_t& slot(std::int32_t key, bool& inserted) {
    std::size_t i = hash(key);
    while (keys_[i] != -1 && keys_[i] != key) i = (i + 1) & mask_;
    inserted = keys_[i] == -1;
    keys_[i] = key;
    return vals_[i];
  }
  std::int32_t find(std::int32_t key) const {
    for (std::size_t i = hash(key);; i = (i + 1) & mask_) {
      if (keys_[i] == key) return vals_[i];
      if (keys_[i] == -1) return -1;
    }
  }

 private:
  std::size_t hash(std::int32_t key) const {
    return (static_cast<std::uint32_t>(key) * 2654435761u) & mask_;
  }
  std::vector<std::int32_t> keys_, vals_;
  std::size_t mask_ = 0;
};

struct Scratch {
  EdgeMap starts;  // edge → first segment starting there (others via next_same_start)
  EdgeMap ends;    // edge → a segment ending there
  std::vector<std::int32_t> next_same_start;
  std::vector<Segment> segments;
  std::vector<char> used;
};

// The crossing point of the plane with the edge p0-p1, always evaluated from the edge's lower
// vertex index so both facets sharing the edge get identical coordinates. The vertex on or above
// the plane may lie exactly on it: then the point is that vertex.
Eigen::Vector2d crossing(const Eigen::Vector3d& p0, const Eigen::Vector3d& p1, double z) {
  if (p0.z() == z) return p0.head<2>();
  if (p1.z() == z) return p1.head<2>();
  const double t = (z - p0.z()) / (p1.z() - p0.z());
  return p0.head<2>() + t * (p1.head<2>() - p0.head<2>());
}

Eigen::Vector2d edge_point(const Mesh& mesh, std::int32_t e, double z) {
  const Edge& edge = mesh.edges[static_cast<std::size_t>(e)];
  return crossing(mesh.vertices[static_cast<std::size_t>(edge.v0)], mesh.vertices[static_cast<std::size_t>(edge.v1)], z);
}

void collect_segments(const Mesh& mesh, std::span<const std::int32_t> faces, double z,
                      std::vector<Segment>& out) {
  out.clear();
  for (const std::int32_t f : faces) {
    const auto& tri = mesh.faces[static_cast<std::size_t>(f)];
    const Eigen::Vector3d* v[3];
    bool above[3];
    for (int k = 0; k < 3; ++k) {
      v[k] = &mesh.vertices[static_cast<std::size_t>(tri[k])];
      above[k] = v[k]->z() >= z;
    }
    int start = -1, end = -1;
    for (int k = 0; k < 3; ++k) {
      const bool a = above[k], b = above[(k + 1) % 3];
      if (a && !b) start = k;
      if (!a && b) end = k;
    }
    if (start < 0 || end < 0) continue;
    const int k1 = (start + 1) % 3;
    const bool lower_first = tri[start] < tri[k1];  // the edge's canonical order, as edge_point uses
    const Eigen::Vector2d p = lower_first ? crossing(*v[start], *v[k1], z) : crossing(*v[k1], *v[start], z);
    const auto& fe = mesh.face_edges[static_cast<std::size_t>(f)];
    out.push_back({p, fe[start], fe[end], f});
  }
}

// Pick the unused segment that continues at `edge`; on a non-manifold edge several may start
// there: prefer one of the same shell, so touching bodies stay separate loops.
std::int32_t next_segment(const Mesh& mesh, const Scratch& s, std::int32_t edge, std::int32_t shell) {
  std::int32_t fallback = -1;
  for (std::int32_t c = s.starts.find(edge); c >= 0; c = s.next_same_start[static_cast<std::size_t>(c)]) {
    if (s.used[static_cast<std::size_t>(c)]) continue;
    const auto face = static_cast<std::size_t>(s.segments[static_cast<std::size_t>(c)].face);
    if (mesh.shell_id[face] == shell) return c;
    if (fallback < 0) fallback = c;
  }
  return fallback;
}

// Drop vectors of zero length (a facet touching the plane at one vertex) so every contour vector
// has a direction; the loop stays closed because its neighbours share that point.
template <class Chain>
void drop_zero_length(Chain& chain, bool closed) {
  const std::size_t n = chain.facets.size();
  std::size_t w = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t j = closed ? (i + 1) % n : i + 1;
    if (chain.points[i] == chain.points[j]) continue;
    chain.points[w] = chain.points[i];
    chain.facets[w] = chain.facets[i];
    ++w;
  }
  if (!closed) chain.points[w] = chain.points[n];
  chain.facets.resize(w);
  chain.points.resize(closed ? w : w + 1);
}

// Segments by start edge (a list each, in segment order) and by end edge.
void index_segments(Scratch& s) {
  const auto n = static_cast<std::int32_t>(s.segments.size());
  s.next_same_start.assign(static_cast<std::size_t>(n), -1);
  s.used.assign(static_cast<std::size_t>(n), 0);
  s.starts.reset(static_cast<std::size_t>(n));
  s.ends.reset(static_cast<std::size_t>(n));
  for (std::int32_t i = n - 1; i >= 0; --i) {  // reverse, so lists come out in segment order
    const Segment& seg = s.segments[static_cast<std::size_t>(i)];
    bool inserted = false;
    std::int32_t& head = s.starts.slot(seg.start_edge, inserted);
    s.next_same_start[static_cast<std::size_t>(i)] = inserted ? -1 : head;
    head = i;
    s.ends.slot(seg.end_edge, inserted) = i;
  }
}

// Loops (closed, with their shell) and open chains of one slice, as they are traced.
struct Chains {
  std::vector<Loop> loops;
  std::vector<int> loop_shell;
};

// The chain from segment `first`, within its shell: a loop when it comes back to its start, an
// open chain (into slice.open_chains) when it ends on a boundary edge of an open mesh.
void trace_chain(const Mesh& mesh, Scratch& s, std::int32_t first, double z, Chains& c, Slice& slice) {
  const Segment& head = s.segments[static_cast<std::size_t>(first)];
  const std::int32_t shell = mesh.shell_id[static_cast<std::size_t>(head.face)];
  Loop loop;
  std::int32_t cur = first;
  bool closed = false;
  for (;;) {
    s.used[static_cast<std::size_t>(cur)] = 1;
    const Segment& seg = s.segments[static_cast<std::size_t>(cur)];
    loop.points.push_back(seg.start);
    loop.facets.push_back(seg.face);
    if (seg.end_edge == head.start_edge) {  // back where we started
      closed = true;
      break;
    }
    const std::int32_t nxt = next_segment(mesh, s, seg.end_edge, shell);
    if (nxt < 0) {  // the chain ends on a boundary edge of an open mesh
      loop.points.push_back(edge_point(mesh, seg.end_edge, z));
      break;
    }
    cur = nxt;
  }
  if (closed) {
    drop_zero_length(loop, true);
    if (loop.points.size() >= 3) {
      c.loops.push_back(std::move(loop));
      c.loop_shell.push_back(shell);
    }
    return;
  }
  OpenChain chain;
  chain.points = std::move(loop.points);
  chain.facets = std::move(loop.facets);
  drop_zero_length(chain, false);
  slice.open_chains.push_back(std::move(chain));
}

// Open chains closed across gaps no wider than the gap rule (each its own body), or said.
void close_open_chains(const SliceParams& params, double z, Chains& c, Slice& slice) {
  if (slice.open_chains.empty()) return;
  if (params.gap_close_mm > 0.0) {
    std::vector<OpenChain> pending = slice.open_chains;
    for (Loop& loop : slice_detail::close_gaps(pending, params.gap_close_mm, slice.warnings)) {
      c.loops.push_back(std::move(loop));
      c.loop_shell.push_back(-1 - static_cast<int>(c.loop_shell.size()));
    }
  } else {
    slice.warnings.push_back(
        fmt::format("z={:.4f} mm: {} open chain(s) left open (gap rule disabled)", z, slice.open_chains.size()));
  }
}

// Loops of different shells that meet: their union. Where they only touch the union is the
// loops themselves; report (and use) it only when it differs.
void unite_shells(Chains& c, double z, Slice& slice) {
  if (!slice_detail::needs_union(c.loops, c.loop_shell)) return;
  std::vector<Loop> merged = slice_detail::union_of_loops(c.loops);
  for (Loop& loop : merged) slice_detail::compute_area(loop);
  double before = 0.0, after = 0.0;
  for (const Loop& l : c.loops) before += l.area_mm2;
  for (const Loop& l : merged) after += l.area_mm2;
  if (merged.size() != c.loops.size() || std::abs(after - before) > 1e-12 * std::max(1.0, std::abs(before))) {
    slice_detail::compute_nesting(merged);
    c.loops = std::move(merged);
    slice.warnings.push_back(fmt::format("z={:.4f} mm: overlapping shells, contours replaced by their union", z));
  }
}

Slice slice_one(const Mesh& mesh, std::span<const std::int32_t> faces, double z,
                const SliceParams& params, Scratch& s) {
  Slice slice;
  slice.z_mm = z;
  collect_segments(mesh, faces, z, s.segments);
  index_segments(s);
  const auto n = static_cast<std::int32_t>(s.segments.size());
  Chains c;
  // Open chains first, from segments nothing leads into, so each is traced from its true start.
  for (std::int32_t i = 0; i < n; ++i) {
    if (s.used[static_cast<std::size_t>(i)]) continue;
    if (s.ends.find(s.segments[static_cast<std::size_t>(i)].start_edge) < 0) trace_chain(mesh, s, i, z, c, slice);
  }
  for (std::int32_t i = 0; i < n; ++i)
    if (!s.used[static_cast<std::size_t>(i)]) trace_chain(mesh, s, i, z, c, slice);
  close_open_chains(params, z, c, slice);
  for (Loop& loop : c.loops) slice_detail::compute_area(loop);
  slice_detail::compute_nesting(c.loops);
  unite_shells(c, z, slice);
  slice.loops = std::move(c.loops);
  return slice;
}

}  // namespace

int Slice::outer_count() const {
  return static_cast<int>(std::count_if(loops.begin(), loops.end(), [](const Loop& l) { return !l.is_hole(); }));
}
int Slice::hole_count() const {
  return static_cast<int>(std::count_if(loops.begin(), loops.end(), [](const Loop& l) { return l.is_hole(); }));
}
double Slice::net_area_mm2() const {
  double a = 0.0;
  for (const Loop& l : loops) a += l.area_mm2;
  return a;
}

ContourVector Slice::vector(const Mesh& mesh, std::size_t loop, std::size_t index) const {
  const Loop& l = loops.at(loop);
  ContourVector v;
  v.start_mm = l.points.at(index);
  v.end_mm = l.points[(index + 1) % l.points.size()];
  v.z_mm = z_mm;
  v.facet = l.facets[index];
  if (v.facet >= 0) {
    const Eigen::Vector2d mid = 0.5 * (v.start_mm + v.end_mm);
    v.normal = surface_normal_at(mesh, v.facet, Eigen::Vector3d(mid.x(), mid.y(), z_mm));
    v.surface_id = mesh.surface_id[static_cast<std::size_t>(v.facet)];
  } else {
    // A gap vector: the horizontal normal on its right, where the outside is (t × z).
    const Eigen::Vector2d d = (v.end_mm - v.start_mm).normalized();
    v.normal = Eigen::Vector3d(d.y(), -d.x(), 0.0);
  }
  return v;
}

double planes_by_step(double height_mm, double step_mm) {
  if (!(step_mm > 0.0) || !(height_mm > 0.0)) return 0.0;
  return std::floor(height_mm / step_mm + 0.5);
}

std::vector<double> heights_by_step(double height_mm, double step_mm) {
  std::vector<double> zs;
  const double planes = planes_by_step(height_mm, step_mm);
  if (!(planes <= static_cast<double>(kMaxSlicePlanes))) return zs;
  const auto count = static_cast<std::size_t>(planes);
  zs.reserve(count);
  for (std::size_t i = 0; i < count; ++i) zs.push_back((static_cast<double>(i) + 0.5) * step_mm);
  return zs;
}

std::expected<void, Error> for_each_slice(const Mesh& mesh, std::span<const double> zs, const SliceParams& params,
                                          const std::function<void(std::size_t, Slice&&)>& visit) {
  if (mesh.faces.empty()) return std::unexpected(Error{ErrorCode::empty_mesh, "slice: the mesh has no facets"});
  if (zs.size() > kMaxSlicePlanes)
    return std::unexpected(Error{ErrorCode::invalid_argument,
                                 fmt::format("slice: {} planes asked for, at most {}", zs.size(), kMaxSlicePlanes)});
  for (std::size_t i = 0; i < zs.size(); ++i)
    if (!std::isfinite(zs[i]))
      return std::unexpected(Error{ErrorCode::invalid_argument, fmt::format("slice: height #{} is not finite", i)});
  if (!(params.gap_close_mm >= 0.0))
    return std::unexpected(Error{ErrorCode::invalid_argument, "slice: gap_close_mm must be >= 0"});

  // Bucket facets by the planes they cross (CSR): a facet crosses z iff zmin < z <= zmax.
  std::vector<std::size_t> order(zs.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return zs[a] < zs[b]; });
  std::vector<double> sorted_z(zs.size());
  for (std::size_t i = 0; i < order.size(); ++i) sorted_z[i] = zs[order[i]];

  const slice_detail::FacetBuckets buckets = slice_detail::bucket_facets(mesh, sorted_z);

  tbb::enumerable_thread_specific<Scratch> scratch;
  auto run = [&](std::size_t k) {
    std::span<const std::int32_t> faces(buckets.faces.data() + buckets.offsets[k],
                                        buckets.faces.data() + buckets.offsets[k + 1]);
    visit(order[k], slice_one(mesh, faces, sorted_z[k], params, scratch.local()));
  };
  if (params.parallel) {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, sorted_z.size()),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                        for (std::size_t k = r.begin(); k != r.end(); ++k) run(k);
                      });
  } else {
    for (std::size_t k = 0; k < sorted_z.size(); ++k) run(k);
  }
  return {};
}

std::expected<std::vector<Slice>, Error> slice_mesh(const Mesh& mesh, std::span<const double> zs,
                                                    const SliceParams& params) {
  std::vector<Slice> out(zs.size());
  auto done = for_each_slice(mesh, zs, params, [&](std::size_t i, Slice&& s) { out[i] = std::move(s); });
  if (!done) return std::unexpected(done.error());
  return out;
}

}  // namespace lamina
