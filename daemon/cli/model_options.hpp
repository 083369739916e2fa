#pragma once
#include "model_loading.hpp"

#include <CLI/CLI.hpp>

namespace lamina::cli {

// The options every model-reading command shares.
inline void add_model_options(CLI::App& cmd, ModelOptions& o) {
  cmd.add_option("MODEL", o.path, "Model file: STL (binary or ASCII), OBJ, 3MF, or STEP / IGES (.step .stp .iges .igs)")
      ->required();
  cmd.add_option("--chord-tolerance", o.chord_tolerance_mm,
                 "STEP / IGES: the most a triangle strays from its surface, mm (plan: a tenth of --tolerance)")
      ->check(CLI::Range(1e-4, 10.0));
  cmd.add_option("--surface-normals", o.surface_normals,
                 "STEP / IGES: exact (the B-rep surface's normal in the bevel plan) or facet (the triangles')")
      ->check(CLI::IsMember({"exact", "facet"}))
      ->capture_default_str();
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
