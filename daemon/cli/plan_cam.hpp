#pragma once
// The cut-program options of `lamina plan` (issue 4): as typed (mm, degrees, the machine and
// materials files) and the settings they resolve to; the stage itself is core's (plan_job.hpp).
#include "lamina/core/cam_settings.hpp"
#include "lamina/core/plan_report.hpp"
#include "machine_config.hpp"
#include "materials_config.hpp"
#include "plan_options.hpp"

#include <CLI/CLI.hpp>

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
  std::optional<std::string> jet_compensation;  // auto (default), off, taper, full
  std::string kerf_file;                        // default: kerf.toml beside the materials file
  std::optional<double> corner_error_mm;        // the trail-back corners' allowance (JetCorners)
  std::optional<std::string> inside_corners;    // slow (default) or keep
  bool no_programs = false;  // stop after the stack (no nesting, programs, drawings)
};

void add_cam_options(CLI::App& cmd, CamOptions& o);
// The cut settings the options and files resolve to (lamina/core/cam_settings.hpp).
std::expected<CamSettings, Error> resolve_cam_settings(const CamOptions& o);

// The sheet table a person reads, from the report.
void print_sheet_table(std::FILE* out, const PlanReport& report);

}  // namespace lamina::cli
