#pragma once
// The materials file (config/materials.toml): the cutting head's [jet] and one [[material]] table per
// material the feed models know. Units are in the key names and converted to SI here, once:
//
//   [jet]                              # optional; absent keys keep JetSetup's defaults
//   pressure_mpa = 380                 # (0, 1000]
//   orifice_diameter_mm = 0.33         # (0, 5]
//   focus_diameter_mm = 1.02           # (0, 10]
//   abrasive_g_per_min = 350           # (0, 10000]
//   water_density_kg_per_m3 = 998      # [900, 1100]
//   discharge_coefficient = 1.0        # (0, 1]
//
//   [[material]]
//   name = "aluminium 6061-T6"         # required, unique (matched exactly against stock.toml)
//   density_kg_per_m3 = 2700           # optional, > 0
//   specific_energy_j_per_mm3 = 7.7    # μ_job of paper eq. 3, > 0   } at least one of the two
//   machinability = 213                # Zeng & Kim N_m, > 0          }
//
// Any other key is an error naming the file, line and key.
#include "lamina/core/cam_settings.hpp"
#include "lamina/core/error.hpp"
#include "lamina/core/feed.hpp"

#include <expected>
#include <functional>
#include <map>
#include <string>
#include <string_view>

namespace lamina::cli {

// Errors: io_error (cannot read), parse_error ("FILE:LINE: what").
std::expected<MaterialsConfig, Error> load_materials(const std::string& path);
std::expected<MaterialsConfig, Error> parse_materials_toml(std::string_view text, const std::string& source_name);

}  // namespace lamina::cli
