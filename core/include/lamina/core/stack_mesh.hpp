#pragma once
// The layered part as it will be after cutting, as a triangle mesh: each layer a closed solid
// whose walls are what its cuts leave, the bonding gaps as gaps. Written as stack.stl so anyone
// can load it next to the CAD model.
#include "lamina/core/bevel.hpp"
#include "lamina/core/triangle_soup.hpp"

#include <string>

namespace lamina {

// One closed, consistently outward-wound shell per layer outline group (outer + its holes).
// Rings of edge points at the layer's faces, its sub-slices and the midpoints between them,
// walls between consecutive rings, caps on exactly the ring vertices. Where the cuts tangle a
// ring (it crosses itself or another ring of its group, runs backwards, turns inside out), the
// offending points are pulled back to where they were on the neighbouring clean ring, so the
// shell stays closed and keeps a little more material there than the cuts do. Layers with no
// bonding gap touch face to face: each shell is closed, but the STL as a whole then has
// coincident faces (non-manifold where the layers meet).
TriangleSoup stack_mesh(const BevelPlan& plan);

// Binary STL bytes (80-byte header, count, 50 bytes per facet), facet normals from winding.
// The header is padded with spaces to 80 bytes (cut at 80) and prefixed with "binary STL: " if
// it would otherwise start with "solid". More than 2³²−1 facets throw std::length_error.
std::string binary_stl_bytes(const TriangleSoup& soup, const std::string& header);

}  // namespace lamina
