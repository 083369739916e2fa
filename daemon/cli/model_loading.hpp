#pragma once
// The CLI's edge: parse unit/axis options once, read the file, build the mesh, time each phase.
#include "lamina/core/mesh.hpp"
#include "lamina/core/plan_report.hpp"

#include <expected>
#include <memory>
#include <optional>
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
  // STEP / IGES only: the tessellation's chord tolerance (mm). Unset: `lamina plan` takes a tenth
  // of its --tolerance, check and slice CadReadOptions' default (0.02 mm).
  std::optional<double> chord_tolerance_mm;
  // STEP / IGES only: "exact" (the bevel plan reads the B-rep surface's normal) or "facet" (the
  // triangles' own, as for a mesh; to measure what the exact ones change).
  std::string surface_normals = "exact";
};

struct LoadedModel {
  std::string format;
  std::optional<BrepData> brep;  // a STEP / IGES file's faces and solids (without the per-triangle tables)
  std::vector<ReadNote> notes;
  Mesh mesh;
  double read_s = 0.0;
  double topology_s = 0.0;
};

MeshParams mesh_params_from(const ModelOptions& options);
std::expected<LoadedModel, Error> load_model(const ModelOptions& options);

// What a STEP / IGES file told us, as the plan report and `lamina check --json` give it
// (model.cad); nullopt for a mesh. cad_lines: the same for a person, one line each.
std::optional<ReportCad> cad_report(const LoadedModel& model, const ModelOptions& options);
std::vector<std::string> cad_lines(const ReportCad& cad);
// What a plan's deviation is measured against, read and put in `planned`'s frame: the same B-rep
// file tessellated finer (the CAD surface to within that chord), or another file of the same part
// in the same coordinates (`lamina plan part.stl --deviation-against part.step`).
struct DeviationReference {
  std::shared_ptr<const Mesh> mesh;
  ReportDeviationReference echo;
};
std::expected<DeviationReference, Error> load_reference(const ModelOptions& options, const Mesh& planned);

// A size that suggests the wrong --units (issue 17, item 8): a part under 10 mm at its largest
// read as mm (an inch file: 25.4 times that), or a part larger than the sheet read as inches
// (a mm file). Said, not refused: both can be meant.
inline constexpr double kSmallestPlausiblePartMm = 10.0;
// Shells that overlap (issue 17, item 8: a 9-shell OBJ passed `lamina check` without a word):
// the solid is their union, and the summary's volume, a sum over shells, counts the overlap
// more than once. Found by slicing at kShellProbePlanes heights; several shells only.
inline constexpr int kShellProbePlanes = 64;
std::optional<std::string> overlapping_shells(const Mesh& mesh);

std::optional<std::string> implausible_size(const Mesh& mesh, const ModelOptions& options, double sheet_longest_mm);

}  // namespace lamina::cli
