#pragma once
// STEP and IGES through OpenCASCADE (the lamina_step library; lamina_core stays free of OCCT).
// The file's solids, with their assembly placements, tessellated so that edges shared by two
// faces are meshed once (watertight without welding) and each triangle carries its B-rep face.
#include "lamina/core/error.hpp"
#include "lamina/core/triangle_soup.hpp"

#include <cstdint>
#include <expected>
#include <filesystem>

namespace lamina {

struct CadReadOptions {
  // The most a triangle may stray from its surface (BRepMesh's linear deflection), mm. The CLI
  // derives it from the plan's tolerance (a tenth of it) unless --chord-tolerance is given.
  double chord_tolerance_mm = 0.02;
  // The most the normals of two neighbouring triangles on one face may turn (angular deflection).
  double angle_tolerance_rad = 0.35;
  // Reading, transferring and tessellating stop here (limit_exceeded): a hostile file or a chord
  // far too fine for the part must not hold the planner for ever.
  double max_seconds = 300;
  // A file above this size is refused before it is parsed (a 50 MB assembly is a big one).
  std::uint64_t max_file_bytes = std::uint64_t{1} << 30;
  // The most triangles the tessellation may make (checked as each solid is meshed).
  std::uint64_t max_triangles = 50'000'000;
  // Names from the file (products, components) in notes and errors; off for files someone else
  // named (laminad), as MeshReadOptions::quote_file_text.
  bool quote_file_text = true;
};

// Read a STEP or IGES file (by its extension). Corners in mm whatever the file's unit (which the
// result's brep->length_unit names). Errors: io_error (cannot open), unknown_format or
// parse_error (not a STEP / IGES file, or one the reader rejects), truncated_file, empty_mesh
// (no solid: only surfaces, or nothing), limit_exceeded (size, time, triangles).
std::expected<TriangleSoup, Error> read_cad_file(const std::filesystem::path& path, const CadReadOptions& options = {});

}  // namespace lamina
