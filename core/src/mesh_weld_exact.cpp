// Step 1–2a of build_mesh: drop non-finite facets, merge bit-identical corners (+0 and -0 count
// as identical).
//
// The corners' float bit patterns are hashed into open-addressing tables that hold the whole
// key (one memory access per probe, prefetched a few corners ahead). The work is split into
// partitions by hash, one table each, run in parallel; every partition meets its points in file
// order, so merging the partitions by first corner gives exactly the serial numbering (order of
// first appearance), whatever the number of threads.
#include "mesh_internal.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cstdint>
#include <cstring>

namespace lamina::mesh_detail {
namespace {

using Key = std::array<std::uint32_t, 3>;

inline std::uint64_t hash_key(const Key& k) {
  const std::uint64_t a = (static_cast<std::uint64_t>(k[0]) | (static_cast<std::uint64_t>(k[1]) << 32));
  return mix64(a * 0x9E3779B97F4A7C15ULL ^ (static_cast<std::uint64_t>(k[2]) + 0x632BE59BD9B4E019ULL));
}

// The bit pattern of a corner, with -0 read as +0 (equal values, one vertex).
inline Key key_of(const TriangleSoup& soup, std::size_t c) {
  const Eigen::Vector3f p = soup.corners[c].array() + 0.0f;
  Key k;
  std::memcpy(k.data(), p.data(), sizeof k);
  return k;
}

constexpr std::size_t kAhead = 16;  // prefetch distance (corners)

struct Slot {
  Key k;
  std::int32_t idx;  // -1: empty
};

struct Part {
  std::vector<Slot> table;
  std::vector<Key> keys;             // this partition's points, in order of first appearance
  std::vector<std::int32_t> first;  // the corner where each was first seen
};

// One partition: the corners whose hash falls in it, in file order. corner_point gets
// local id · parts + p.
void weld_part(const TriangleSoup& soup, const std::vector<char>& facet_ok, std::size_t p, std::size_t parts,
               Part& part, std::vector<std::int32_t>& corner_point) {
  const std::size_t nc = soup.triangle_count() * 3;
  auto owner = [parts](std::uint64_t h) { return static_cast<std::size_t>((h >> 40) % parts); };
  // A closed mesh has about one vertex per six corners: start at load <= 0.5 for that and
  // double whenever the load passes 0.5.
  std::size_t cap = pow2_at_least(nc / (3 * parts) + 1);
  std::size_t mask = cap - 1;
  part.table.assign(cap, Slot{{0, 0, 0}, -1});
  part.keys.reserve(nc / (5 * parts) + 16);
  part.first.reserve(nc / (5 * parts) + 16);
  auto grow = [&] {
    cap <<= 1;
    mask = cap - 1;
    part.table.assign(cap, Slot{{0, 0, 0}, -1});
    for (std::size_t i = 0; i < part.keys.size(); ++i) {
      std::size_t s = hash_key(part.keys[i]) & mask;
      while (part.table[s].idx >= 0) s = (s + 1) & mask;
      part.table[s] = Slot{part.keys[i], static_cast<std::int32_t>(i)};
    }
  };

  std::uint64_t ring[kAhead];
  for (std::size_t c = 0; c < std::min(nc, kAhead); ++c) ring[c] = hash_key(key_of(soup, c));
  for (std::size_t c = 0; c < nc; ++c) {
    const std::uint64_t h = ring[c % kAhead];
    if (c + kAhead < nc) {
      const std::uint64_t ha = hash_key(key_of(soup, c + kAhead));
      ring[c % kAhead] = ha;
      if (owner(ha) == p) __builtin_prefetch(&part.table[ha & mask]);
    }
    if (!facet_ok[c / 3]) {
      if (p == 0) corner_point[c] = -1;
      continue;
    }
    if (owner(h) != p) continue;
    const Key k = key_of(soup, c);
    std::size_t s = h & mask;
    std::int32_t found = -1;
    while (part.table[s].idx >= 0) {
      const Key& t = part.table[s].k;
      if (((t[0] ^ k[0]) | (t[1] ^ k[1]) | (t[2] ^ k[2])) == 0) {
        found = part.table[s].idx;
        break;
      }
      s = (s + 1) & mask;
    }
    if (found < 0) {
      found = static_cast<std::int32_t>(part.keys.size());
      part.keys.push_back(k);
      part.first.push_back(static_cast<std::int32_t>(c));
      part.table[s] = Slot{k, found};
      if (part.keys.size() * 2 > cap) grow();
    }
    corner_point[c] = found * static_cast<std::int32_t>(parts) + static_cast<std::int32_t>(p);
  }
  part.table = {};
}

}  // namespace

ExactWeld exact_weld(const TriangleSoup& soup) {
  ExactWeld ex;
  const std::size_t nf = soup.triangle_count();
  const std::size_t nc = nf * 3;

  std::vector<char> facet_ok(nf);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nf, 1 << 16), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t f = r.begin(); f != r.end(); ++f)
      facet_ok[f] = soup.corners[3 * f].allFinite() && soup.corners[3 * f + 1].allFinite() &&
                    soup.corners[3 * f + 2].allFinite();
  });
  for (std::size_t f = 0; f < nf; ++f) {
    if (facet_ok[f]) continue;
    if (ex.nan_facets == 0) ex.first_nan_facet = f;
    ++ex.nan_facets;
  }

  // Ids are stored as local · parts + p in an int32 while the partitions run.
  const bool split = nc >= (std::size_t{1} << 16) && nc <= static_cast<std::size_t>(INT32_MAX / 8);
  const std::size_t parts =
      split ? static_cast<std::size_t>(std::clamp(tbb::this_task_arena::max_concurrency(), 1, 8)) : 1;
  std::vector<Part> part(parts);
  reserve_hinted(ex.corner_point, nc);
  ex.corner_point.resize(nc);
  tbb::parallel_for(std::size_t{0}, parts,
                    [&](std::size_t p) { weld_part(soup, facet_ok, p, parts, part[p], ex.corner_point); });

  if (parts == 1) {
    ex.keys = std::move(part[0].keys);
    return ex;
  }

  // Merge by first corner: the numbering a single table would give.
  std::size_t total = 0;
  for (const Part& pt : part) total += pt.keys.size();
  ex.keys.resize(total);
  std::vector<std::vector<std::int32_t>> global(parts);
  std::vector<std::size_t> at(parts, 0);
  for (std::size_t p = 0; p < parts; ++p) global[p].resize(part[p].keys.size());
  for (std::size_t g = 0; g < total; ++g) {
    std::size_t best = parts;
    std::int32_t best_first = 0;
    for (std::size_t p = 0; p < parts; ++p) {
      if (at[p] < part[p].first.size() && (best == parts || part[p].first[at[p]] < best_first)) {
        best = p;
        best_first = part[p].first[at[p]];
      }
    }
    ex.keys[g] = part[best].keys[at[best]];
    global[best][at[best]++] = static_cast<std::int32_t>(g);
  }
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nc, 1 << 16), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t c = r.begin(); c != r.end(); ++c) {
      const std::int32_t v = ex.corner_point[c];
      if (v < 0) continue;
      const auto p = static_cast<std::size_t>(v) % parts, local = static_cast<std::size_t>(v) / parts;
      ex.corner_point[c] = global[p][local];
    }
  });
  return ex;
}

}  // namespace lamina::mesh_detail
