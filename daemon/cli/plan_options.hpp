#pragma once
// `lamina plan` options: as typed (mm and degrees, the stock as text or a file) and, once
// validated, in the units the core uses (mm and radians). Plan lengths are always millimetres;
// --units is the model file's unit only.
#include "lamina/core/error.hpp"
#include "lamina/core/plan_job.hpp"
#include "lamina/core/stock.hpp"
#include "model_loading.hpp"

#include <CLI/CLI.hpp>

#include <expected>
#include <string>
#include <string_view>
#include <vector>

namespace lamina::cli {

// As given on the command line.
struct PlanOptions {
  ModelOptions model;
  std::string stock_list = "1,2.5,5,10";  // --stock, thicknesses in mm
  bool stock_list_given = false;
  std::string stock_file;                 // --stock-file, TOML
  double bond_mm = 0.0;
  double sub_slice_mm = 0.5;
  double tolerance_mm = 0.2;
  double tilt_max_deg = 60.0;
  std::string side = "outside";
  std::string strategy = "curved";
  std::string layering = "optimal";
  double deviation_step_mm = 0.1;
  bool compare_strategies = false;
  std::string out_dir;
  bool json = false;
  bool all_rows = false;
  int progress_fd = -1;                   // --progress-fd: phase lines for laminad (plan_progress.hpp)
  std::string as_cut_dir;                 // --as-cut: the sheets as cut (sheet-<n>.ascut.json), measured beside the plan
  // STEP / IGES: the chord of the tessellation the deviation is measured against (0: the planned
  // tessellation itself). Unset: a tenth of the planned one's.
  std::optional<double> deviation_chord_mm;
  std::string deviation_against;  // --deviation-against FILE: another file of the part (its STEP)
};

// What the deviation is measured against (--deviation-against, or a B-rep model tessellated
// finer), as the options to read it with; nullopt: the planned mesh itself. `planned`: the model's
// options with the planning chord filled in.
std::optional<ModelOptions> deviation_reference_options(const PlanOptions& o, const ModelOptions& planned);

// Validated, in core units: PlanSettings (lamina/core/plan_job.hpp).

void add_plan_options(CLI::App& cmd, PlanOptions& o);

// "1,2.5,5,10" → {1, 2.5, 5, 10}; an error message naming the bad item otherwise.
std::expected<std::vector<double>, std::string> parse_thickness_list(std::string_view text);

// Reads the stock file when given; errors name the file (and line).
std::expected<PlanSettings, Error> resolve_plan_settings(const PlanOptions& o);


}  // namespace lamina::cli
