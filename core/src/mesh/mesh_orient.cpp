// Steps 6a and 8 of build_mesh: shells, consistent winding and surfaces, in one walk.
//
// A shell is a connected component of facets joined through manifold edges (exactly two
// facets). Non-manifold edges do not join: two solids touching along an edge stay two shells
// and are oriented independently. Walking a shell, each facet gets the orientation that makes
// every shared edge run in opposite directions in its two facets; the smaller side of each shell
// is then turned over (which way is out for the whole shell is decided in mesh_shells.cpp).
//
// The same walk grows the surfaces: a facet reached across an edge whose dihedral angle is at
// most the threshold joins the current surface and is expanded at once; one reached across a
// sharp edge waits, and seeds a new surface if no smooth path reaches it first. The angle uses
// the raw normals with the relative orientation just found, so it equals the angle between the
// final normals. Surfaces are connected components of smooth edges, so the sets do not depend on
// the walk; their ids are renumbered by lowest facet afterwards.
#include "mesh/mesh_internal.hpp"

#include <cmath>

namespace lamina::mesh_detail {
namespace {

// Per-facet walk state, one byte each so the whole table stays in cache.
constexpr std::uint8_t kVisited = 1, kFlip = 2, kSurfaced = 4;

// The breadth-first walk over a mesh's facets: shells (connected by edges), the winding each
// facet needs to agree with its neighbours, and surfaces (joined across edges no sharper than
// the threshold).
struct ShellWalk {
  Mesh& m;
  const Adjacency& adj;
  double min_cos;
  OrientResult& r;
  std::vector<std::uint8_t> state;
  ShellFaces sf;
  std::vector<char> shell_conflict;
  // sf.order doubles as the breadth-first queue of the current surface (a facet enters it once,
  // when its surface is known); pending holds facets reached across sharp edges.
  std::vector<std::int32_t> pending;
  std::size_t head = 0, conflicts_twice = 0;
  std::int32_t surfaces = 0;

  // Prefetch two stages ahead along the queue: the across entries of a facet 16 places on, and
  // the normals of the neighbours of the facet 8 places on (normals are the one large array the
  // walk reads at random).
  void prefetch_ahead() const {
    if (head + 16 < sf.order.size()) __builtin_prefetch(&adj.across[3 * static_cast<std::size_t>(sf.order[head + 16])]);
    if (head + 8 < sf.order.size()) {
      const std::int32_t* ahead = &adj.across[3 * static_cast<std::size_t>(sf.order[head + 8])];
      for (int k = 0; k < 3; ++k)
        if (ahead[k] >= 0) __builtin_prefetch(&m.normals[static_cast<std::size_t>(ahead[k] >> 1)]);
    }
  }

  // Facet fu's k-th neighbour, in shell s and surface sid; fu's turn and normal as the walk
  // took them from the queue.
  void visit(std::size_t fu, std::size_t k, std::int32_t s, std::int32_t sid, std::uint8_t flip_f,
             const Eigen::Vector3d& nf_) {
    const std::int32_t a = adj.across[3 * fu + k];
    if (a < 0) return;
    const auto gu = static_cast<std::size_t>(a >> 1);
    // g must be turned over when, after f's own turn, both run the same way.
    const std::uint8_t want = flip_f ^ ((a & 1) ? kFlip : 0);
    std::uint8_t sg = state[gu];
    bool fresh = false;
    if (!(sg & kVisited)) {
      sg = static_cast<std::uint8_t>(kVisited | want);
      m.shell_id[gu] = s;
      fresh = true;
    } else if ((sg & kFlip) != want) {
      // Seen once from each side: a non-orientable shell (a Möbius-like strip).
      if (conflicts_twice == 0) {
        const Edge& ed = m.edges[static_cast<std::size_t>(m.face_edges[fu][k])];
        r.first_conflict =
            0.5 * (m.vertices[static_cast<std::size_t>(ed.v0)] + m.vertices[static_cast<std::size_t>(ed.v1)]);
      }
      ++conflicts_twice;
      shell_conflict[static_cast<std::size_t>(s)] = 1;
    }
    if (!(sg & kSurfaced)) {
      const double d = nf_.dot(m.normals[gu]);
      if ((flip_f == (sg & kFlip) ? d : -d) >= min_cos) {
        sg |= kSurfaced;
        m.surface_id[gu] = sid;
        sf.order.push_back(static_cast<std::int32_t>(gu));
      } else if (fresh) {
        pending.push_back(static_cast<std::int32_t>(gu));
      }
    }
    state[gu] = sg;
  }

  // The shell that holds `seed`, surface by surface.
  void walk_shell(std::size_t seed) {
    const auto s = static_cast<std::int32_t>(sf.begin.size());
    sf.begin.push_back(static_cast<std::int32_t>(sf.order.size()));
    shell_conflict.push_back(0);
    state[seed] = kVisited;
    m.shell_id[seed] = s;
    pending.push_back(static_cast<std::int32_t>(seed));
    while (!pending.empty()) {
      const std::int32_t f0 = pending.back();
      pending.pop_back();
      if (state[static_cast<std::size_t>(f0)] & kSurfaced) continue;
      const std::int32_t sid = surfaces++;
      state[static_cast<std::size_t>(f0)] |= kSurfaced;
      m.surface_id[static_cast<std::size_t>(f0)] = sid;
      sf.order.push_back(f0);
      while (head < sf.order.size()) {
        prefetch_ahead();
        const auto fu = static_cast<std::size_t>(sf.order[head++]);
        const std::uint8_t flip_f = state[fu] & kFlip;
        const Eigen::Vector3d nf_ = m.normals[fu];
        for (std::size_t k = 0; k < 3; ++k) visit(fu, k, s, sid, flip_f, nf_);
      }
    }
  }

  // Keep the majority orientation of each shell; turn the others over.
  void keep_majority() {
    const std::size_t shells = sf.begin.size() - 1;
    for (std::size_t s = 0; s < shells; ++s) {
      std::size_t flips = 0;
      const auto b = static_cast<std::size_t>(sf.begin[s]), e = static_cast<std::size_t>(sf.begin[s + 1]);
      for (std::size_t i = b; i < e; ++i) flips += (state[static_cast<std::size_t>(sf.order[i])] & kFlip) ? 1 : 0;
      if (2 * flips > e - b)
        for (std::size_t i = b; i < e; ++i) state[static_cast<std::size_t>(sf.order[i])] ^= kFlip;
    }
    for (std::size_t f = 0; f < m.faces.size(); ++f) {
      if (!(state[f] & kFlip)) continue;
      if (r.facets_flipped == 0) r.first_flipped = centroid(m, f);
      flip_face(m, f);
      ++r.facets_flipped;
    }
  }
};

}  // namespace

OrientResult orient_shells(Mesh& m, const Adjacency& adj, double sharp_angle_rad) {
  OrientResult r;
  const std::size_t nf = m.faces.size();
  m.shell_id.assign(nf, -1);
  m.surface_id.assign(nf, -1);
  // Joined when the angle between normals is <= the threshold, i.e. cos(angle) >= cos(threshold).
  // 1e-6 rad of slack: corners come from float32 files, so a dihedral angle that is exactly the
  // threshold by design (a 12-gon's 30°) is off by ~1e-7 rad either way and must still join.
  ShellWalk w{m, adj, std::cos(sharp_angle_rad + 1e-6), r, std::vector<std::uint8_t>(nf, 0), {}, {}, {}};
  w.sf.order.reserve(nf);
  for (std::size_t seed = 0; seed < nf; ++seed)
    if (!(w.state[seed] & kVisited)) w.walk_shell(seed);
  w.sf.begin.push_back(static_cast<std::int32_t>(w.sf.order.size()));
  r.winding_conflicts = w.conflicts_twice / 2;
  r.surfaces = w.surfaces;
  w.keep_majority();
  outward_shells(m, adj, w.sf, w.shell_conflict, r);
  return r;
}

}  // namespace lamina::mesh_detail
