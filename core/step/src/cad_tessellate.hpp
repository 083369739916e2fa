#pragma once
// The placed solids of a CAD document as triangles, each on its B-rep face, with the faces'
// surfaces and the corners' exact normals (lamina/core/brep_surfaces.hpp).
#include "cad_document.hpp"

#include "lamina/core/triangle_soup.hpp"

namespace lamina::step_detail {

std::expected<TriangleSoup, Error> tessellate(const CadDocument& doc, const std::string& name,
                                              const CadReadOptions& options, Deadline& deadline);

}  // namespace lamina::step_detail
