#pragma once
// Structural checks every built mesh must pass, whatever its defects.
#include <lamina/core/mesh.hpp>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

namespace lamina::mesh_test {

// Counts how many facets of an edge run v0 → v1 minus those running v1 → v0.
inline int edge_balance(const Mesh& m, std::size_t e) {
  const Edge& ed = m.edges[e];
  int sum = 0;
  for (std::int32_t i = 0; i < ed.face_count; ++i) {
    const auto f = static_cast<std::size_t>(m.edge_faces[static_cast<std::size_t>(ed.face_begin + i)]);
    for (int k = 0; k < 3; ++k) {
      if (m.face_edges[f][static_cast<std::size_t>(k)] != static_cast<std::int32_t>(e)) continue;
      sum += m.faces[f][static_cast<std::size_t>(k)] == ed.v0 ? 1 : -1;
    }
  }
  return sum;
}

// Returns an empty string when the mesh is well-formed, else the first problem found.
inline std::string structure_problem(const Mesh& m) {
  const std::size_t nf = m.faces.size(), nv = m.vertices.size();
  if (m.normals.size() != nf || m.surface_id.size() != nf || m.shell_id.size() != nf || m.face_edges.size() != nf)
    return "per-facet arrays differ in size";
  if (m.edge_faces.size() != 3 * nf) return "edge_faces is not 3 per facet";
  std::size_t total = 0;
  for (std::size_t e = 0; e < m.edges.size(); ++e) {
    const Edge& ed = m.edges[e];
    if (!(ed.v0 < ed.v1) || ed.v0 < 0 || static_cast<std::size_t>(ed.v1) >= nv) return "edge " + std::to_string(e) + " vertices";
    if (e > 0 && !(std::pair(m.edges[e - 1].v0, m.edges[e - 1].v1) < std::pair(ed.v0, ed.v1)))
      return "edges not sorted/unique at " + std::to_string(e);
    if (ed.face_count < 1 || ed.face_begin != static_cast<std::int32_t>(total)) return "edge CSR at " + std::to_string(e);
    total += static_cast<std::size_t>(ed.face_count);
  }
  if (total != 3 * nf) return "edge face counts do not sum to 3F";
  std::vector<char> used(nv, 0);
  for (std::size_t f = 0; f < nf; ++f) {
    const auto& t = m.faces[f];
    for (int k = 0; k < 3; ++k) {
      const std::int32_t a = t[static_cast<std::size_t>(k)], b = t[static_cast<std::size_t>((k + 1) % 3)];
      if (a < 0 || static_cast<std::size_t>(a) >= nv) return "facet vertex out of range";
      used[static_cast<std::size_t>(a)] = 1;
      if (a == b) return "facet with repeated vertex";
      const auto e = m.face_edges[f][static_cast<std::size_t>(k)];
      if (e < 0 || static_cast<std::size_t>(e) >= m.edges.size()) return "face_edges out of range";
      const Edge& ed = m.edges[static_cast<std::size_t>(e)];
      if (ed.v0 != std::min(a, b) || ed.v1 != std::max(a, b)) return "face_edges does not match facet " + std::to_string(f);
      const auto* fs = m.edge_faces.data() + ed.face_begin;
      if (std::find(fs, fs + ed.face_count, static_cast<std::int32_t>(f)) == fs + ed.face_count)
        return "facet missing from its edge's list";
    }
    const Eigen::Vector3d n = (m.vertices[static_cast<std::size_t>(t[1])] - m.vertices[static_cast<std::size_t>(t[0])])
                                  .cross(m.vertices[static_cast<std::size_t>(t[2])] - m.vertices[static_cast<std::size_t>(t[0])])
                                  .normalized();
    if (std::abs(m.normals[f].norm() - 1.0) > 1e-12 || (n - m.normals[f]).norm() > 1e-9)
      return "normal of facet " + std::to_string(f) + " is not the unit winding normal";
    if (m.shell_id[f] < 0 || m.shell_id[f] >= m.summary.shells) return "shell id out of range";
    if (m.surface_id[f] < 0 || m.surface_id[f] >= m.summary.surfaces) return "surface id out of range";
  }
  if (std::find(used.begin(), used.end(), 0) != used.end()) return "unused vertex";
  double zmin = 1e300;
  for (const auto& v : m.vertices) zmin = std::min(zmin, v.z());
  if (zmin != 0.0) return "lowest point is not at z = 0";
  if (m.shell_info.size() != static_cast<std::size_t>(m.summary.shells)) return "shell_info size";
  for (const auto& d : m.defects) {
    if (d.message.empty() || d.message.find('\n') != std::string::npos) return "defect message not one line: " + d.code;
  }
  return {};
}

// build_mesh that must succeed and give a well-formed mesh (test failures otherwise).
inline Mesh build_checked(const TriangleSoup& soup, const MeshParams& params = {}) {
  auto r = build_mesh(soup, params);
  EXPECT_TRUE(r.has_value()) << (r ? "" : r.error().message);
  if (!r) return Mesh{};
  EXPECT_EQ(structure_problem(*r), "");
  return std::move(*r);
}

}  // namespace lamina::mesh_test
