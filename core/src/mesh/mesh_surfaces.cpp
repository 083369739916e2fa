// Steps 7–8 of build_mesh: facet normals from the winding, and canonical surface ids.
//
// A surface is what the paper reads as a CAD face: facets joined across manifold edges whose
// dihedral angle (between the two facet normals) is at most the sharp-edge threshold; boundary
// and non-manifold edges always bound surfaces. They are grown in mesh_orient.cpp; here they are
// numbered 0..S-1 in order of their lowest facet, as growing from seeds in facet order would.
#include "mesh/mesh_internal.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>


namespace lamina::mesh_detail {

void compute_normals(Mesh& m) {
  const std::size_t nf = m.faces.size();
  m.normals.resize(nf);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nf, 16384), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t f = r.begin(); f != r.end(); ++f) {
      const Tri& t = m.faces[f];
      const Eigen::Vector3d& a = m.vertices[static_cast<std::size_t>(t[0])];
      const Eigen::Vector3d n =
          (m.vertices[static_cast<std::size_t>(t[1])] - a).cross(m.vertices[static_cast<std::size_t>(t[2])] - a);
      const double len = n.norm();
      // Degenerate facets were dropped, so len > 0; keep a finite value regardless.
      m.normals[f] = len > 0.0 ? Eigen::Vector3d(n / len) : Eigen::Vector3d::UnitZ();
    }
  });
}

void renumber_surfaces(Mesh& m, int surfaces) {
  std::vector<std::int32_t> remap(static_cast<std::size_t>(surfaces), -1);
  std::int32_t next = 0;
  for (auto& id : m.surface_id) {
    auto& r = remap[static_cast<std::size_t>(id)];
    if (r < 0) r = next++;
    id = r;
  }
}

}  // namespace lamina::mesh_detail
