#pragma once
// What a mesh reader returns: triangles as stored, before any welding or repair.
#include <Eigen/Core>

#include "lamina/core/brep_surfaces.hpp"

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

namespace lamina {

// Something the reader noticed that is not fatal (a padded file, zero stored normals, ...).
struct ReadNote {
  std::string code;     // stable, e.g. "trailing_bytes", "stored_normals_zero"
  std::string message;  // one readable line with counts and where
};

struct TriangleSoup {
  // Three corners per triangle, in file order, in the file's own units.
  std::vector<Eigen::Vector3f> corners;
  std::string format;  // "stl-binary", "stl-ascii", "obj", "3mf", "step", "iges"
  std::vector<ReadNote> notes;
  // From a B-rep file only (STEP, IGES): each triangle's CAD face and the faces' surfaces.
  std::optional<BrepData> brep;

  std::size_t triangle_count() const { return corners.size() / 3; }
};

}  // namespace lamina
