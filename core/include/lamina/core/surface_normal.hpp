#pragma once
// The surface's normal at a point of a facet: exact on a B-rep's analytic faces (plane, cylinder,
// cone, sphere, torus), the corners' exact normals interpolated on its other faces (B-spline …),
// and the facet's own normal on a mesh. Always unit and on the facet normal's side.
#include "lamina/core/mesh.hpp"

#include <Eigen/Core>

#include <cstdint>

namespace lamina {

// `point` lies on (or next to) facet `facet`, in the build frame (mm).
Eigen::Vector3d surface_normal_at(const Mesh& mesh, std::int32_t facet, const Eigen::Vector3d& point);

}  // namespace lamina
