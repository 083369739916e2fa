#pragma once
#include "model_loading.hpp"

#include <CLI/CLI.hpp>

namespace lamina::cli {

// The options every model-reading command shares.
inline void add_model_options(CLI::App& cmd, ModelOptions& o) {
  cmd.add_option("MODEL", o.path, "Mesh file: STL (binary or ASCII), OBJ or 3MF")->required();
  cmd.add_option("--units", o.units, "Units of the file")->check(CLI::IsMember({"mm", "in"}))->capture_default_str();
  auto* axis = cmd.add_option("--axis", o.axis, "Build direction (becomes +Z)")
                   ->check(CLI::IsMember({"x", "y", "z"}))
                   ->capture_default_str();
  cmd.add_option("--direction", o.direction, "Any build direction X,Y,Z instead of --axis")
      ->delimiter(',')
      ->expected(3)
      ->excludes(axis);
  cmd.add_option("--sharp-angle", o.sharp_angle_deg, "Dihedral angle (degrees) above which an edge bounds a surface")
      ->check(CLI::Range(0.0, 180.0))
      ->capture_default_str();
  cmd.add_option("--weld-tolerance", o.weld_tolerance_rel, "Vertex weld distance, fraction of the bounding-box diagonal")
      ->check(CLI::Range(0.0, 1e-2))
      ->capture_default_str();
  cmd.add_flag("--no-quote-input", o.no_quote_input,
               "Errors and notes about MODEL say where and what was expected but never quote its bytes "
               "(for a file someone else named: laminad passes it)");
}

}  // namespace lamina::cli
