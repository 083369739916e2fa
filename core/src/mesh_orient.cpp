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
#include "mesh_internal.hpp"

#include <cmath>

namespace lamina::mesh_detail {
namespace {

// True when facets f and g run along their shared edge (side k of f) in the same direction.
inline bool same_direction(const Tri& f, int k, const Tri& g) {
  const std::int32_t a = f[static_cast<std::size_t>(k)], b = f[static_cast<std::size_t>((k + 1) % 3)];
  // Bitwise, not short-circuit: the outcome is data-dependent and branches would mispredict.
  return ((g[0] == a) & (g[1] == b)) | ((g[1] == a) & (g[2] == b)) | ((g[2] == a) & (g[0] == b));
}

}  // namespace

OrientResult orient_shells(Mesh& m, const Adjacency& adj, double sharp_angle_rad) {
  OrientResult r;
  const std::size_t nf = m.faces.size();
  m.shell_id.assign(nf, -1);
  m.surface_id.assign(nf, -1);
  std::vector<char> flip(nf, 0);
  // Joined when the angle between normals is <= the threshold, i.e. cos(angle) >= cos(threshold).
  // 1e-6 rad of slack: corners come from float32 files, so a dihedral angle that is exactly the
  // threshold by design (a 12-gon's 30°) is off by ~1e-7 rad either way and must still join.
  const double min_cos = std::cos(sharp_angle_rad + 1e-6);

  ShellFaces sf;
  sf.order.reserve(nf);
  std::vector<char> shell_conflict;
  std::vector<std::int32_t> smooth, pending;  // facets to expand now / seeds of later surfaces
  std::size_t conflicts_twice = 0;
  std::int32_t surfaces = 0;

  for (std::size_t seed = 0; seed < nf; ++seed) {
    if (m.shell_id[seed] >= 0) continue;
    const auto s = static_cast<std::int32_t>(sf.begin.size());
    sf.begin.push_back(static_cast<std::int32_t>(sf.order.size()));
    shell_conflict.push_back(0);
    m.shell_id[seed] = s;
    pending.push_back(static_cast<std::int32_t>(seed));
    while (!pending.empty()) {
      const std::int32_t f0 = pending.back();
      pending.pop_back();
      if (m.surface_id[static_cast<std::size_t>(f0)] >= 0) continue;
      const std::int32_t sid = surfaces++;
      m.surface_id[static_cast<std::size_t>(f0)] = sid;
      smooth.push_back(f0);
      while (!smooth.empty()) {
        const std::int32_t f = smooth.back();
        smooth.pop_back();
        sf.order.push_back(f);
        const auto fu = static_cast<std::size_t>(f);
        const Tri& tf = m.faces[fu];
        for (int k = 0; k < 3; ++k) {
          const std::int32_t g = adj.across[3 * fu + static_cast<std::size_t>(k)];
          if (g < 0) continue;
          const auto gu = static_cast<std::size_t>(g);
          // g must be turned over when, after f's own turn, both run the same way.
          const char want = static_cast<char>(flip[fu] ^ (same_direction(tf, k, m.faces[gu]) ? 1 : 0));
          bool fresh = false;
          if (m.shell_id[gu] < 0) {
            m.shell_id[gu] = s;
            flip[gu] = want;
            fresh = true;
          } else if (flip[gu] != want) {
            // Seen once from each side: a non-orientable shell (a Möbius-like strip).
            if (conflicts_twice == 0) {
              const Edge& ed = m.edges[static_cast<std::size_t>(m.face_edges[fu][static_cast<std::size_t>(k)])];
              r.first_conflict = 0.5 * (m.vertices[static_cast<std::size_t>(ed.v0)] +
                                        m.vertices[static_cast<std::size_t>(ed.v1)]);
            }
            ++conflicts_twice;
            shell_conflict[static_cast<std::size_t>(s)] = 1;
          }
          if (m.surface_id[gu] >= 0) continue;
          const double d = m.normals[fu].dot(m.normals[gu]);
          if ((flip[fu] == flip[gu] ? d : -d) >= min_cos) {
            m.surface_id[gu] = sid;
            smooth.push_back(g);
          } else if (fresh) {
            pending.push_back(g);
          }
        }
      }
    }
  }
  sf.begin.push_back(static_cast<std::int32_t>(sf.order.size()));
  r.winding_conflicts = conflicts_twice / 2;
  r.surfaces = surfaces;

  // Keep the majority orientation of each shell; turn the others over.
  const std::size_t shells = sf.begin.size() - 1;
  for (std::size_t s = 0; s < shells; ++s) {
    std::size_t flips = 0;
    const auto b = static_cast<std::size_t>(sf.begin[s]), e = static_cast<std::size_t>(sf.begin[s + 1]);
    for (std::size_t i = b; i < e; ++i) flips += static_cast<std::size_t>(flip[static_cast<std::size_t>(sf.order[i])]);
    if (2 * flips > e - b) {
      for (std::size_t i = b; i < e; ++i) flip[static_cast<std::size_t>(sf.order[i])] ^= 1;
    }
  }
  for (std::size_t f = 0; f < nf; ++f) {
    if (!flip[f]) continue;
    if (r.facets_flipped == 0) r.first_flipped = centroid(m, f);
    flip_face(m, f);
    ++r.facets_flipped;
  }

  outward_shells(m, adj, sf, shell_conflict, r);
  return r;
}

}  // namespace lamina::mesh_detail
