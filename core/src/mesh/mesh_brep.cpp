// Step 8 of build_mesh for a B-rep file: its faces are the surfaces (not the dihedral rule), and
// each facet keeps its corners' exact normals, in its own corner order after orientation.
#include "mesh/mesh_internal.hpp"

namespace lamina::mesh_detail {

namespace {

BrepFace to_build_frame(BrepFace face, const Eigen::Matrix3d& rotation, double scale, double z_shift) {
  face.origin = rotation * face.origin * scale - Eigen::Vector3d(0, 0, z_shift);
  face.axis = (rotation * face.axis).normalized();
  face.radius_mm *= scale;
  face.minor_radius_mm *= scale;
  return face;
}

}  // namespace

void apply_brep(Mesh& m, const BrepData& brep, const BrepCarry& carry, const Eigen::Matrix3d& rotation, double scale,
                double z_shift) {
  m.brep_faces.reserve(brep.faces.size());
  for (const BrepFace& face : brep.faces) m.brep_faces.push_back(to_build_frame(face, rotation, scale, z_shift));
  m.corner_normals.resize(m.faces.size());
  const Eigen::Matrix3f rot = rotation.cast<float>();
  for (std::size_t f = 0; f < m.faces.size(); ++f) {
    const auto src = static_cast<std::size_t>(carry.source_triangle[f]);
    m.surface_id[f] = brep.triangle_face[src];
    // Orientation may have turned the facet round: follow each vertex to its corner in the file.
    for (std::size_t k = 0; k < 3; ++k) {
      std::size_t j = 0;
      while (j < 2 && carry.faces_as_read[f][j] != m.faces[f][k]) ++j;
      m.corner_normals[f][k] = rot * brep.corner_normals[3 * src + j];
    }
  }
}

}  // namespace lamina::mesh_detail
