#include "materials_config.hpp"

#include <fmt/format.h>
#include "toml_file.hpp"

#include <cmath>
#include <optional>

namespace lamina::cli {
namespace {

// A key of the file: its unit conversion to the SI field and its allowed range (in file units).
struct NumberKey {
  std::string_view key;
  double to_si;          // file unit → SI
  double low, high;      // allowed range in the file's unit
  bool low_inclusive;    // [low or (low
};

// A TOML integer or float within the key's range, returned in SI.
std::expected<double, Error> number(const std::string& source, const NumberKey& k, const toml::node& node) {
  std::optional<double> v;
  if (const auto* i = node.as_integer()) v = static_cast<double>(i->get());
  if (const auto* f = node.as_floating_point()) v = f->get();
  if (!v) return std::unexpected(toml_error(source, node.source(), fmt::format("{} must be a number", k.key)));
  const bool above = k.low_inclusive ? *v >= k.low : *v > k.low;
  if (!std::isfinite(*v) || !above || *v > k.high)
    return std::unexpected(toml_error(source, node.source(),
                                       fmt::format("{} = {} is out of range (must be in {}{}, {}])", k.key, *v,
                                                   k.low_inclusive ? "[" : "(", k.low, k.high)));
  return *v * k.to_si;
}

// The units at the edge: every conversion factor of the file is here.
constexpr NumberKey kPressure{"pressure_mpa", 1e6, 0.0, 1000.0, false};
constexpr NumberKey kOrifice{"orifice_diameter_mm", 1e-3, 0.0, 5.0, false};
constexpr NumberKey kFocus{"focus_diameter_mm", 1e-3, 0.0, 10.0, false};
constexpr NumberKey kAbrasive{"abrasive_g_per_min", 1e-3 / 60.0, 0.0, 10000.0, false};
constexpr NumberKey kWaterDensity{"water_density_kg_per_m3", 1.0, 900.0, 1100.0, true};
constexpr NumberKey kDischarge{"discharge_coefficient", 1.0, 0.0, 1.0, false};
constexpr NumberKey kDensity{"density_kg_per_m3", 1.0, 0.0, 50000.0, false};
constexpr NumberKey kSpecificEnergy{"specific_energy_j_per_mm3", 1e9, 0.0, 1e6, false};  // J/mm³ → J/m³
constexpr NumberKey kMachinability{"machinability", 1.0, 0.0, 1e5, false};

std::expected<JetSetup, Error> read_jet(const std::string& source, const toml::table& t) {
  JetSetup jet;
  for (const auto& [key, node] : t) {
    const std::string_view k = key.str();
    const NumberKey* spec = nullptr;
    double* field = nullptr;
    for (auto [s, f] : {std::pair{&kPressure, &jet.pressure_pa}, std::pair{&kOrifice, &jet.orifice_diameter_m},
                        std::pair{&kFocus, &jet.focus_diameter_m}, std::pair{&kAbrasive, &jet.abrasive_rate_kg_per_s},
                        std::pair{&kWaterDensity, &jet.water_density_kg_per_m3},
                        std::pair{&kDischarge, &jet.discharge_coefficient}})
      if (k == s->key) spec = s, field = f;
    if (!spec)
      return std::unexpected(toml_error(
          source, key.source(),
          fmt::format("unknown key '{}' in [jet] (known: pressure_mpa, orifice_diameter_mm, focus_diameter_mm, "
                      "abrasive_g_per_min, water_density_kg_per_m3, discharge_coefficient)",
                      k)));
    auto v = number(source, *spec, node);
    if (!v) return std::unexpected(v.error());
    *field = *v;
  }
  return jet;
}

std::expected<Material, Error> read_material(const std::string& source, const toml::table& t) {
  Material m;
  bool has_name = false;
  for (const auto& [key, node] : t) {
    const std::string_view k = key.str();
    if (k == "name") {
      const auto* s = node.as_string();
      if (!s || s->get().empty())
        return std::unexpected(toml_error(source, node.source(), "name must be a non-empty string"));
      m.name = s->get();
      has_name = true;
      continue;
    }
    const NumberKey* spec = nullptr;
    double* field = nullptr;
    for (auto [s, f] : {std::pair{&kDensity, &m.density_kg_per_m3}, std::pair{&kSpecificEnergy, &m.specific_energy_j_per_m3},
                        std::pair{&kMachinability, &m.machinability}})
      if (k == s->key) spec = s, field = f;
    if (!spec)
      return std::unexpected(toml_error(
          source, key.source(),
          fmt::format("unknown key '{}' in [[material]] (known: name, density_kg_per_m3, specific_energy_j_per_mm3, "
                      "machinability)",
                      k)));
    auto v = number(source, *spec, node);
    if (!v) return std::unexpected(v.error());
    *field = *v;
  }
  if (!has_name) return std::unexpected(toml_error(source, t.source(), "[[material]] without name"));
  if (m.specific_energy_j_per_m3 == 0.0 && m.machinability == 0.0)
    return std::unexpected(toml_error(
        source, t.source(),
        fmt::format("material '{}' has neither specific_energy_j_per_mm3 nor machinability: no feed model can use it", m.name)));
  return m;
}

}  // namespace

std::expected<MaterialsConfig, Error> parse_materials_toml(std::string_view text, const std::string& source_name) {
  auto parsed = parse_toml(text, source_name);
  if (!parsed) return std::unexpected(parsed.error());
  const toml::table& doc = *parsed;
  MaterialsConfig config;
  for (const auto& [key, node] : doc) {
    const std::string_view k = key.str();
    if (k == "jet") {
      const auto* t = node.as_table();
      if (!t) return std::unexpected(toml_error(source_name, node.source(), "jet must be a table: [jet]"));
      auto jet = read_jet(source_name, *t);
      if (!jet) return std::unexpected(jet.error());
      config.jet = *jet;
    } else if (k == "material") {
      const auto* list = node.as_array();
      if (!list || !list->is_array_of_tables())
        return std::unexpected(
            toml_error(source_name, node.source(), "material must be written [[material]], one table per material"));
      for (const toml::node& entry : *list) {
        auto m = read_material(source_name, *entry.as_table());
        if (!m) return std::unexpected(m.error());
        if (config.materials.contains(m->name))
          return std::unexpected(toml_error(source_name, entry.source(), fmt::format("material '{}' given twice", m->name)));
        config.materials.emplace(m->name, std::move(*m));
      }
    } else {
      return std::unexpected(toml_error(
          source_name, key.source(), fmt::format("unknown key '{}' (the file holds [jet] and [[material]] tables)", k)));
    }
  }
  if (config.materials.empty())
    return std::unexpected(Error{ErrorCode::parse_error, fmt::format("{}: no [[material]] in the file", source_name)});
  return config;
}

std::expected<MaterialsConfig, Error> load_materials(const std::string& path) {
  auto text = read_config_file(path, "materials");
  if (!text) return std::unexpected(text.error());
  return parse_materials_toml(*text, path);
}

}  // namespace lamina::cli
