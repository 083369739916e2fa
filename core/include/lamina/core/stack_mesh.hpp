#pragma once
// The layered part as it will be after cutting, as a triangle mesh: each layer a closed solid
// whose walls are what its cuts leave, the bonding gaps as gaps. Written as stack.stl so anyone
// can load it next to the CAD model.
#include "lamina/core/bevel.hpp"
#include "lamina/core/triangle_soup.hpp"

#include <string>

namespace lamina {

// One closed, consistently outward-wound shell per layer outline group (outer + its holes).
TriangleSoup stack_mesh(const BevelPlan& plan);

// Binary STL bytes (80-byte header, count, 50 bytes per facet), facet normals from winding.
std::string binary_stl_bytes(const TriangleSoup& soup, const std::string& header);

}  // namespace lamina
