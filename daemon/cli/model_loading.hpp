#pragma once
// The CLI's edge: parse unit/axis options once, read the file, build the mesh, time each phase.
#include "lamina/core/mesh.hpp"

#include <expected>
#include <string>
#include <vector>

namespace lamina::cli {

struct ModelOptions {
  std::string path;
  std::string units = "mm";  // mm | in — converted here, once; everything inside is mm
  std::string axis = "z";    // x | y | z — the build direction
  std::vector<double> direction;  // or any vector (3 numbers); replaces axis when given
  double sharp_angle_deg = 30.0;
  double weld_tolerance_rel = 1e-7;
  // --no-quote-input: reader messages describe the file's bytes instead of quoting them (laminad
  // plans files its clients name; MeshReadOptions::quote_file_text).
  bool no_quote_input = false;
};

struct LoadedModel {
  std::string format;
  std::vector<ReadNote> notes;
  Mesh mesh;
  double read_s = 0.0;
  double topology_s = 0.0;
};

MeshParams mesh_params_from(const ModelOptions& options);
std::expected<LoadedModel, Error> load_model(const ModelOptions& options);

}  // namespace lamina::cli
