// Step 4 of build_mesh: unique undirected edges with their facets (CSR).
//
// Counting sort of the 3·F facet sides on their lower vertex, written straight into the
// edge_faces array as side ids (3·f + k); then, per vertex bucket and in parallel, a small sort
// by (higher vertex, side) that makes each edge's sides contiguous; then the edges, face_edges
// and the facet-across-each-side table are written and the side ids become facet ids in place.
// No map, no per-edge allocation, and no temporary bigger than the outputs.
#include "mesh/mesh_internal.hpp"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>

namespace lamina::mesh_detail {
namespace {

struct Side {
  std::int32_t other;  // the higher vertex of the side
  std::int32_t fk;     // facet * 3 + local side index
};

inline bool side_less(const Side& a, const Side& b) {
  return a.other != b.other ? a.other < b.other : a.fk < b.fk;
}

inline std::int32_t higher_vertex(const std::vector<Tri>& faces, std::int32_t fk) {
  const Tri& t = faces[static_cast<std::size_t>(fk / 3)];
  const int k = fk % 3;
  return std::max(t[static_cast<std::size_t>(k)], t[static_cast<std::size_t>((k + 1) % 3)]);
}

// Insertion sort: a bucket holds a handful of sides (about three on a closed mesh).
inline void sort_sides(Side* b, Side* e) {
  if (e - b > 32) {
    std::sort(b, e, side_less);
    return;
  }
  for (Side* i = b + 1; i < e; ++i) {
    const Side x = *i;
    Side* j = i;
    while (j > b && side_less(x, *(j - 1))) {
      *j = *(j - 1);
      --j;
    }
    *j = x;
  }
}

constexpr std::size_t kGrain = 8192;

std::size_t lower_vertex(const Tri& t, int k) {
  return static_cast<std::size_t>(std::min(t[static_cast<std::size_t>(k)], t[static_cast<std::size_t>((k + 1) % 3)]));
}

// Counting sort of the sides on their lower vertex, in parallel over chunks of facets: each
// chunk counts, the prefix sums give each chunk its place inside each bucket, each chunk
// scatters. (The order inside a bucket is fixed by the sort below, not by the chunking.) Side
// ids go into `buckets`; returns each vertex's bucket start (nv + 1 entries).
std::vector<std::int32_t> bucket_sides(std::size_t nv, const std::vector<Tri>& faces, std::vector<std::int32_t>& buckets) {
  const std::size_t nf = faces.size();
  const std::size_t chunks =
      nf < (std::size_t{1} << 16) ? 1 : static_cast<std::size_t>(std::clamp(tbb::this_task_arena::max_concurrency(), 1, 8));
  auto chunk_begin = [&](std::size_t t) { return nf * t / chunks; };
  std::vector<std::vector<std::int32_t>> fill(chunks);
  tbb::parallel_for(std::size_t{0}, chunks, [&](std::size_t t) {
    auto& cnt = fill[t];
    cnt.assign(nv, 0);
    for (std::size_t f = chunk_begin(t); f < chunk_begin(t + 1); ++f)
      for (int k = 0; k < 3; ++k) ++cnt[lower_vertex(faces[f], k)];
  });
  std::vector<std::int32_t> start(nv + 1, 0);
  std::int32_t run = 0;
  for (std::size_t v = 0; v < nv; ++v) {
    start[v] = run;
    for (std::size_t t = 0; t < chunks; ++t) {
      const std::int32_t c = fill[t][v];
      fill[t][v] = run;
      run += c;
    }
  }
  start[nv] = run;
  buckets.resize(nf * 3);
  tbb::parallel_for(std::size_t{0}, chunks, [&](std::size_t t) {
    auto& at = fill[t];
    for (std::size_t f = chunk_begin(t); f < chunk_begin(t + 1); ++f)
      for (int k = 0; k < 3; ++k)
        buckets[static_cast<std::size_t>(at[lower_vertex(faces[f], k)]++)] =
            static_cast<std::int32_t>(3 * f + static_cast<std::size_t>(k));
  });
  return start;
}

// Sorts each bucket by (higher vertex, side id); returns where each vertex's edges start.
std::vector<std::int32_t> sort_buckets(std::size_t nv, const std::vector<Tri>& faces, const std::vector<std::int32_t>& start,
                                       std::vector<std::int32_t>& buckets) {
  std::vector<std::int32_t> edge_start(nv + 1, 0);
  tbb::enumerable_thread_specific<std::vector<Side>> scratch;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nv, kGrain), [&](const tbb::blocked_range<std::size_t>& r) {
    auto& buf = scratch.local();
    for (std::size_t v = r.begin(); v != r.end(); ++v) {
      const auto b = static_cast<std::size_t>(start[v]), e = static_cast<std::size_t>(start[v + 1]);
      buf.resize(e - b);
      for (std::size_t i = b; i < e; ++i) buf[i - b] = Side{higher_vertex(faces, buckets[i]), buckets[i]};
      sort_sides(buf.data(), buf.data() + buf.size());
      std::int32_t n = 0;
      for (std::size_t i = 0; i < buf.size(); ++i) {
        buckets[b + i] = buf[i].fk;
        if (i == 0 || buf[i].other != buf[i - 1].other) ++n;
      }
      edge_start[v + 1] = n;
    }
  });
  for (std::size_t v = 0; v < nv; ++v) edge_start[v + 1] += edge_start[v];
  return edge_start;
}

// What build_edges writes, per vertex bucket.
struct EdgeTables {
  const std::vector<Tri>& faces;
  std::vector<Edge>& edges;
  std::vector<std::int32_t>& edge_faces;
  std::vector<Tri>& face_edges;
  std::vector<std::int32_t>& across;

  // The edges whose lower vertex is v, from its sorted bucket [b, end); edges not shared by
  // exactly two facets go to `odd`. Side ids become facet ids.
  void emit(std::size_t v, std::size_t e, std::size_t b, std::size_t end, std::vector<std::int32_t>& odd) {
    for (std::size_t i = b; i < end;) {
      const std::int32_t hi = higher_vertex(faces, edge_faces[i]);
      std::size_t j = i + 1;
      while (j < end && higher_vertex(faces, edge_faces[j]) == hi) ++j;
      const auto count = static_cast<std::int32_t>(j - i);
      edges[e] = Edge{static_cast<std::int32_t>(v), hi, static_cast<std::int32_t>(i), count};
      if (count == 2)
        pair_across(v, edge_faces[i], edge_faces[i + 1]);
      else {
        odd.push_back(static_cast<std::int32_t>(e));
        for (std::size_t s = i; s < j; ++s) across[static_cast<std::size_t>(edge_faces[s])] = -1;
      }
      for (std::size_t s = i; s < j; ++s) {
        const std::int32_t fk = edge_faces[s];
        face_edges[static_cast<std::size_t>(fk / 3)][static_cast<std::size_t>(fk % 3)] = static_cast<std::int32_t>(e);
        edge_faces[s] = fk / 3;
      }
      ++e;
      i = j;
    }
  }
  // Two sides of one edge: each facet's neighbour across it, and whether they run the same way.
  void pair_across(std::size_t v, std::int32_t s0, std::int32_t s1) {
    // A side runs "up" when it starts at this bucket's (lower) vertex v.
    const bool up0 = faces[static_cast<std::size_t>(s0 / 3)][static_cast<std::size_t>(s0 % 3)] == static_cast<std::int32_t>(v);
    const bool up1 = faces[static_cast<std::size_t>(s1 / 3)][static_cast<std::size_t>(s1 % 3)] == static_cast<std::int32_t>(v);
    const std::int32_t same = up0 == up1 ? 1 : 0;
    across[static_cast<std::size_t>(s0)] = (s1 / 3) * 2 + same;
    across[static_cast<std::size_t>(s1)] = (s0 / 3) * 2 + same;
  }
};

}  // namespace

Adjacency build_edges(std::size_t vertex_count, const std::vector<Tri>& faces, std::vector<Edge>& edges,
                      std::vector<std::int32_t>& edge_faces, std::vector<Tri>& face_edges) {
  const std::size_t nv = vertex_count;
  Adjacency adj;
  // edge_faces is the bucket storage until the edges are emitted.
  const std::vector<std::int32_t> start = bucket_sides(nv, faces, edge_faces);
  const std::vector<std::int32_t> edge_start = sort_buckets(nv, faces, start, edge_faces);

  // Emit edges, face_edges and the across table.
  edges.resize(static_cast<std::size_t>(edge_start[nv]));
  face_edges.resize(faces.size());
  adj.across.resize(faces.size() * 3);
  EdgeTables tables{faces, edges, edge_faces, face_edges, adj.across};
  tbb::enumerable_thread_specific<std::vector<std::int32_t>> odd;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nv, kGrain), [&](const tbb::blocked_range<std::size_t>& r) {
    auto& my_odd = odd.local();
    for (std::size_t v = r.begin(); v != r.end(); ++v)
      tables.emit(v, static_cast<std::size_t>(edge_start[v]), static_cast<std::size_t>(start[v]),
                  static_cast<std::size_t>(start[v + 1]), my_odd);
  });
  for (const auto& v : odd) adj.odd_edges.insert(adj.odd_edges.end(), v.begin(), v.end());
  std::sort(adj.odd_edges.begin(), adj.odd_edges.end());
  return adj;
}

}  // namespace lamina::mesh_detail
