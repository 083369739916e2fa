#pragma once
// The machine and the materials a plan is cut with, in core units: what `lamina plan` reads from
// config/machine.toml and config/materials.toml (the CLI's loaders fill these), and what the
// cut-program stage of plan_job (plan_job.hpp) needs. Data only; files are read at the edges.
#include "lamina/core/error.hpp"
#include "lamina/core/feed.hpp"
#include "lamina/core/kinematics.hpp"
#include "lamina/core/nest.hpp"
#include "lamina/core/parts.hpp"
#include "lamina/core/post.hpp"
#include "lamina/core/toolpath.hpp"

#include <expected>
#include <functional>
#include <map>
#include <string>
#include <string_view>

namespace lamina {

struct MachineConfig {
  HeadKinematics head;
  PostParams post;
  ToolpathParams cutting;  // includes the jet and the feed model
  NestParams nest;
  double sheet_width_mm = 1250.0;   // for sheets known by thickness only
  double sheet_length_mm = 2500.0;
};

struct MaterialsConfig {
  std::map<std::string, Material, std::less<>> materials;  // by name
  JetSetup jet;
};

// The material of that exact name; invalid_argument listing the known names otherwise.
std::expected<Material, Error> find_material(const MaterialsConfig& config, std::string_view name);

struct CamSettings {
  MachineConfig machine;
  MaterialsConfig materials;
  std::string material_override;  // every sheet is cut as this material ("" : the stock's)
  PartParams parts;
  std::string machine_source, materials_source;  // where they were read, for the report
  std::string kerf_source;  // the kerf calibrations' file, when one was read (docs/jet.md)
};

}  // namespace lamina
