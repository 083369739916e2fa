#pragma once
// The cut-program stage of `lamina plan` (issue 4): parts, nesting on the stock's sheets, one
// toolpath, G-code program and SVG drawing per sheet. Options as typed (mm, degrees, the machine
// and materials files) and the settings they resolve to; the stage itself calls core/ only and
// returns the files' contents — cmd_plan writes them.
#include "lamina/core/bevel.hpp"
#include "lamina/core/nest.hpp"
#include "lamina/core/parts.hpp"
#include "lamina/core/post.hpp"
#include "lamina/core/toolpath.hpp"
#include "machine_config.hpp"
#include "materials_config.hpp"
#include "plan_options.hpp"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <cstdio>
#include <expected>
#include <optional>
#include <string>
#include <vector>

namespace lamina::cli {

// Overrides of the machine file, as typed. Unset: the file's value.
struct CamOptions {
  std::string machine_file;    // default: <config dir>/machine.toml
  std::string materials_file;  // default: <config dir>/materials.toml
  std::optional<std::string> material, nest, post, feed_model;
  std::optional<double> kerf_mm, spacing_mm, margin_mm, lead_in_mm, lead_out_mm, pierce_dwell_s, microjoint_width_mm,
      dowel_diameter_mm;
  std::optional<int> dowels, microjoints, quality;
  std::optional<bool> rtcp, fill_holes;
  bool no_programs = false;  // stop after the stack (no nesting, programs, drawings)
};

struct CamSettings {
  MachineConfig machine;
  MaterialsConfig materials;
  std::string material_override;  // --material: every sheet is cut as this material
  PartParams parts;
  std::string machine_source, materials_source;
};

void add_cam_options(CLI::App& cmd, CamOptions& o);
std::expected<CamSettings, Error> resolve_cam_settings(const CamOptions& o);

// The stock with sizes filled in for sheets known by thickness only (the machine file's default size).
Stock sized_stock(const Stock& stock, const MachineConfig& machine, std::vector<std::string>& warnings);

struct SheetOutput {
  NestedSheet sheet;
  SheetToolpath toolpath;
  PostedProgram program;
  std::string svg;
  std::string program_name, svg_name;  // sheet-<n>.nc, sheet-<n>.svg
  std::string material;
};

struct CamTimings {  // seconds
  double parts = 0.0, nest = 0.0, toolpath = 0.0, post = 0.0, svg = 0.0;
};

struct CamResult {
  std::vector<Part> parts;
  std::vector<SheetOutput> sheets;
  CamTimings timing;
  std::vector<std::string> warnings;
};

// When the rack runs out of sheets (ErrorCode::stock_exhausted), `shortages` (if given) says
// which thicknesses and how many of their layers were placed whole.
std::expected<CamResult, Error> plan_cam(const BevelPlan& plan, const Stock& stock, const CamSettings& settings,
                                         const std::string& title, std::vector<SheetShortage>* shortages = nullptr);

// report.json's "sheets" and "cam" members.
nlohmann::ordered_json sheets_json(const CamResult& r);
nlohmann::ordered_json cam_json(const CamSettings& s, const CamResult& r);
void print_sheet_table(std::FILE* out, const nlohmann::ordered_json& report);

}  // namespace lamina::cli
