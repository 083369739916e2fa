#include "plan_settings.hpp"

#include <array>
#include <cmath>

#include <fmt/format.h>

#include "lamina/core/bevel_profile.hpp"
#include "lamina/core/feed.hpp"
#include "lamina/core/layering.hpp"
#include "lamina/core/nest.hpp"
#include "lamina/core/post.hpp"

namespace lamina::daemon {
namespace {

enum class Kind { number, integer, text, boolean };

struct Setting {
  const char* key;    // API name
  const char* flag;   // lamina plan flag
  Kind kind;
  double min = 0, max = 0;                  // numbers and integers
  std::vector<std::string> choices = {};    // text: allowed values (empty: any non-empty text)
};

const std::vector<Setting>& settings_table() {
  static const std::vector<Setting> table{
      {"units", "--units", Kind::text, 0, 0, {"mm", "in"}},
      {"axis", "--axis", Kind::text, 0, 0, {"x", "y", "z"}},
      {"stock", "--stock", Kind::text},
      {"stock_file", "--stock-file", Kind::text},
      {"bond_mm", "--bond", Kind::number, 0, 10},
      {"sub_slice_mm", "--sub-slice", Kind::number, 0.01, 50},
      {"tolerance_mm", "--tolerance", Kind::number, 0.001, 50},
      {"tilt_max_deg", "--tilt-max", Kind::number, 0, 89},
      // Names of choices come from core's tables (lamina/core/choices.hpp), as the CLI's do.
      {"side", "--side", Kind::text, 0, 0, cut_sides().names()},
      {"strategy", "--strategy", Kind::text, 0, 0, bevel_strategies().names()},
      {"layering", "--layering", Kind::text, 0, 0, layering_methods().names()},
      {"material", "--material", Kind::text},
      {"nest", "--nest", Kind::text, 0, 0, nest_methods().names()},
      {"post", "--post", Kind::text, 0, 0, post_dialects().names()},
      {"feed_model", "--feed-model", Kind::text, 0, 0, feed_models().names()},
      {"rtcp", "--rtcp", Kind::boolean},
      {"quality", "--quality", Kind::integer, 1, 5},
      {"kerf_mm", "--kerf", Kind::number, 0, 10},
      {"spacing_mm", "--spacing", Kind::number, 0, 1000},
      {"margin_mm", "--margin", Kind::number, 0, 1000},
      {"lead_in_mm", "--lead-in", Kind::number, 0, 100},
      {"lead_out_mm", "--lead-out", Kind::number, 0, 100},
      {"pierce_dwell_s", "--pierce-dwell", Kind::number, 0, 600},
      {"microjoints", "--microjoints", Kind::integer, 0, 100},
      {"microjoint_width_mm", "--microjoint-width", Kind::number, 0.01, 50},
      {"dowels", "--dowels", Kind::integer, 0, 64},
      {"dowel_diameter_mm", "--dowel-diameter", Kind::number, 0.5, 100},
      {"fill_holes", "--fill-holes", Kind::boolean},
      {"compare_strategies", "--compare-strategies", Kind::boolean},
      {"jet_compensation", "--jet-compensation", Kind::text, 0, 0, jet_compensation_modes().names()},
      {"corner_error_mm", "--corner-error", Kind::number, 0.001, 10},
      {"inside_corners", "--inside-corners", Kind::text, 0, 0, inside_corner_strategies().names()},
  };
  return table;
}

std::expected<std::string, std::string> value_text(const Setting& s, const nlohmann::json& v) {
  switch (s.kind) {
    case Kind::number: {
      if (!v.is_number()) return std::unexpected(fmt::format("settings.{}: expected a number", s.key));
      const double x = v.get<double>();
      if (!std::isfinite(x) || x < s.min || x > s.max)
        return std::unexpected(fmt::format("settings.{}: {} is outside {} … {}", s.key, x, s.min, s.max));
      return fmt::format("{}", x);
    }
    case Kind::integer: {
      if (!v.is_number_integer()) return std::unexpected(fmt::format("settings.{}: expected an integer", s.key));
      const auto x = v.get<long long>();
      if (x < s.min || x > s.max)
        return std::unexpected(fmt::format("settings.{}: {} is outside {} … {}", s.key, x, s.min, s.max));
      return fmt::format("{}", x);
    }
    case Kind::boolean:
      if (!v.is_boolean()) return std::unexpected(fmt::format("settings.{}: expected true or false", s.key));
      return v.get<bool>() ? "true" : "false";
    case Kind::text: {
      std::string text;
      if (v.is_string()) {
        text = v.get<std::string>();
      } else if (std::string_view(s.key) == "stock" && v.is_number() && v.get<double>() > 0) {
        text = fmt::format("{}", v.get<double>());  // one thickness, as `--set stock=5` gives it
      } else if (std::string_view(s.key) == "stock" && v.is_array()) {
        // The stock as a list of thicknesses in mm, like --stock 1,2.5,5.
        for (const auto& t : v) {
          if (!t.is_number() || t.get<double>() <= 0)
            return std::unexpected("settings.stock: expected positive thicknesses in mm");
          text += (text.empty() ? "" : ",") + fmt::format("{}", t.get<double>());
        }
      } else {
        return std::unexpected(fmt::format("settings.{}: expected text", s.key));
      }
      if (text.empty() || text.size() > 4096 || text.front() == '-')
        return std::unexpected(fmt::format("settings.{}: empty, too long or starting with '-'", s.key));
      if (!s.choices.empty()) {
        bool ok = false;
        for (const std::string& c : s.choices) ok = ok || text == c;
        if (!ok) {
          std::string list;
          for (const std::string& c : s.choices) list += (list.empty() ? "" : ", ") + c;
          return std::unexpected(fmt::format("settings.{}: '{}' is not one of {}", s.key, text, list));
        }
      }
      return text;
    }
  }
  return std::unexpected("unreachable");
}

}  // namespace

std::expected<PlanArgs, std::string> plan_args_from_settings(const nlohmann::json& settings) {
  PlanArgs out;
  if (settings.is_null()) return out;
  if (!settings.is_object()) return std::unexpected("settings: expected an object");
  for (const auto& [key, value] : settings.items()) {
    const Setting* found = nullptr;
    for (const Setting& s : settings_table())
      if (key == s.key) found = &s;
    if (!found) return std::unexpected(fmt::format("settings.{}: unknown setting", key));
    auto text = value_text(*found, value);
    if (!text) return std::unexpected(text.error());
    out.flags.push_back(found->flag);
    out.flags.push_back(*text);
  }
  return out;
}

std::vector<std::string> plan_setting_keys() {
  std::vector<std::string> keys;
  for (const Setting& s : settings_table()) keys.emplace_back(s.key);
  return keys;
}

}  // namespace lamina::daemon
