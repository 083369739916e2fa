#include "machine_config.hpp"

#include <fmt/format.h>
#include "toml_file.hpp"

#include <cmath>
#include <cstdlib>
#include <functional>
#include <map>
#include <numbers>
#include <optional>
#include <vector>

namespace lamina::cli {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;  // the one degree → radian factor of this file

// One key of a section: reads its node into the config, or says what is wrong with it.
using Reader = std::function<std::optional<std::string>(const toml::node&, MachineConfig&)>;

std::optional<double> as_number(const toml::node& n) {
  if (const auto* i = n.as_integer()) return static_cast<double>(i->get());
  if (const auto* f = n.as_floating_point()) return f->get();
  return std::nullopt;
}

// A number in [lo, hi] (lo excluded when open_lo), scaled by `factor` into the target.
Reader number(double lo, bool open_lo, double hi, std::string unit, double factor,
              std::function<void(MachineConfig&, double)> set) {
  return [=](const toml::node& n, MachineConfig& c) -> std::optional<std::string> {
    const auto v = as_number(n);
    if (!v || !std::isfinite(*v)) return fmt::format("must be a number ({})", unit);
    if (*v < lo || (open_lo && *v == lo) || *v > hi)
      return fmt::format("= {} is out of range ({} {} … {} {})", *v, open_lo ? "above" : "from", lo, hi, unit);
    set(c, *v * factor);
    return std::nullopt;
  };
}

Reader whole(long lo, long hi, std::function<void(MachineConfig&, long)> set) {
  return [=](const toml::node& n, MachineConfig& c) -> std::optional<std::string> {
    const auto* i = n.as_integer();
    if (!i || i->get() < lo || i->get() > hi) return fmt::format("must be a whole number {} … {}", lo, hi);
    set(c, static_cast<long>(i->get()));
    return std::nullopt;
  };
}

Reader sign(std::function<void(MachineConfig&, int)> set) {
  return [=](const toml::node& n, MachineConfig& c) -> std::optional<std::string> {
    const auto* i = n.as_integer();
    if (!i || (i->get() != 1 && i->get() != -1)) return "must be 1 or -1";
    set(c, static_cast<int>(i->get()));
    return std::nullopt;
  };
}

Reader flag(std::function<void(MachineConfig&, bool)> set) {
  return [=](const toml::node& n, MachineConfig& c) -> std::optional<std::string> {
    const auto* b = n.as_boolean();
    if (!b) return "must be true or false";
    set(c, b->get());
    return std::nullopt;
  };
}

// A name registered in one of core's choice tables (lamina/core/choices.hpp).
template <class E, class Traits>
Reader choice(const ChoiceTable<E, Traits>& table, std::function<void(MachineConfig&, E)> set) {
  return [&table, set](const toml::node& n, MachineConfig& c) -> std::optional<std::string> {
    const auto* s = n.as_string();
    if (!s) return "must be a string";
    const auto* row = table.find(s->get());
    if (!row) return fmt::format("= \"{}\" is not one of: {}", s->get(), table.names_text());
    set(c, row->value);
    return std::nullopt;
  };
}

// A G-code word list for the valve: letters, digits, '.', '-', spaces; never a comment or newline.
Reader mcode(std::function<void(MachineConfig&, const std::string&)> set) {
  return [=](const toml::node& n, MachineConfig& c) -> std::optional<std::string> {
    const auto* s = n.as_string();
    if (!s || s->get().empty()) return "must be a non-empty string of G-code words, e.g. \"M3\" or \"M62 P0\"";
    for (char ch : s->get())
      if (!(std::isalnum(static_cast<unsigned char>(ch)) || ch == '.' || ch == '-' || ch == ' '))
        return fmt::format("= \"{}\": only letters, digits, '.', '-' and spaces belong in G-code words", s->get());
    set(c, s->get());
    return std::nullopt;
  };
}

using Section = std::map<std::string, Reader, std::less<>>;

std::map<std::string, Section, std::less<>> sections() {
  constexpr double big = 1e9;
  std::map<std::string, Section, std::less<>> s;
  s["head"] = {
      {"pivot_mm", number(0, false, 2000, "mm", 1, [](auto& c, double v) { c.head.pivot_mm = v; })},
      {"a_sign", sign([](auto& c, int v) { c.head.a_sign = v; })},
      {"c_sign", sign([](auto& c, int v) { c.head.c_sign = v; })},
      {"c_offset_deg", number(-360, false, 360, "degrees", kDeg, [](auto& c, double v) { c.head.c_offset_rad = v; })},
      {"a_min_deg", number(-120, false, 0, "degrees", kDeg, [](auto& c, double v) { c.head.a_min_rad = v; })},
      {"a_max_deg", number(0, true, 120, "degrees", kDeg, [](auto& c, double v) { c.head.a_max_rad = v; })},
      {"c_min_deg", number(-big, false, big, "degrees", kDeg, [](auto& c, double v) { c.head.c_min_rad = v; })},
      {"c_max_deg", number(-big, false, big, "degrees", kDeg, [](auto& c, double v) { c.head.c_max_rad = v; })},
      {"rtcp", flag([](auto& c, bool v) { c.head.rtcp = v; })},
  };
  s["post"] = {
      {"dialect", choice<PostDialect>(post_dialects(), [](auto& c, PostDialect v) { c.post.dialect = v; })},
      {"linear_decimals", whole(1, 6, [](auto& c, long v) { c.post.linear_decimals = static_cast<int>(v); })},
      {"angular_decimals", whole(1, 6, [](auto& c, long v) { c.post.angular_decimals = static_cast<int>(v); })},
      {"hold_rotary_within_step", flag([](auto& c, bool v) { c.post.hold_rotary_within_step = v; })},
      {"jet_on", mcode([](auto& c, const std::string& v) { c.post.jet_on = v; })},
      {"jet_off", mcode([](auto& c, const std::string& v) { c.post.jet_off = v; })},
      {"program_number", whole(1, 9999, [](auto& c, long v) { c.post.program_number = static_cast<int>(v); })},
  };
  s["motion"] = {
      {"rapid_mm_per_min", number(0, true, 1e6, "mm/min", 1.0 / 60, [](auto& c, double v) { c.cutting.rapid_mm_per_s = v; })},
      {"safe_z_mm", number(0, true, 1000, "mm", 1, [](auto& c, double v) { c.cutting.safe_z_mm = v; })},
      {"min_feed_mm_per_min", number(0, true, 1e6, "mm/min", 1.0 / 60, [](auto& c, double v) { c.cutting.feed.min_feed_mm_per_s = v; })},
      {"max_feed_mm_per_min", number(0, true, 1e6, "mm/min", 1.0 / 60, [](auto& c, double v) { c.cutting.feed.max_feed_mm_per_s = v; })},
      {"a_max_deg_per_min", number(0, true, 1e7, "degrees/min", kDeg / 60, [](auto& c, double v) { c.cutting.a_max_rad_per_s = v; })},
      {"c_max_deg_per_min", number(0, true, 1e7, "degrees/min", kDeg / 60, [](auto& c, double v) { c.cutting.c_max_rad_per_s = v; })},
      {"park_x_mm", number(-big, false, big, "mm", 1, [](auto& c, double v) { c.cutting.park_mm.x() = v; })},
      {"park_y_mm", number(-big, false, big, "mm", 1, [](auto& c, double v) { c.cutting.park_mm.y() = v; })},
  };
  s["cutting"] = {
      {"kerf_mm", number(0, false, 10, "mm", 1, [](auto& c, double v) { c.cutting.kerf_mm = v; })},
      {"lead_in_mm", number(0, false, 100, "mm", 1, [](auto& c, double v) { c.cutting.lead_in_mm = v; })},
      {"lead_out_mm", number(0, false, 100, "mm", 1, [](auto& c, double v) { c.cutting.lead_out_mm = v; })},
      {"pierce_dwell_s", number(0, false, 600, "s", 1, [](auto& c, double v) { c.cutting.pierce_dwell_s = v; })},
      {"corner_angle_deg", number(0, false, 180, "degrees", kDeg, [](auto& c, double v) { c.cutting.corner_angle_rad = v; })},
      {"corner_min_fraction", number(0, true, 1, "", 1, [](auto& c, double v) { c.cutting.corner_min_fraction = v; })},
      {"microjoints", whole(0, 100, [](auto& c, long v) { c.cutting.microjoints = static_cast<int>(v); })},
      {"microjoint_width_mm", number(0, true, 50, "mm", 1, [](auto& c, double v) { c.cutting.microjoint_width_mm = v; })},
      {"part_on_right", flag([](auto& c, bool v) { c.cutting.part_on_right = v; })},
  };
  s["feed"] = {
      {"model", choice<FeedModel>(feed_models(), [](auto& c, FeedModel v) { c.cutting.feed.model = v; })},
      {"quality", whole(1, 5, [](auto& c, long v) { c.cutting.feed.quality = static_cast<int>(v); })},
  };
  s["nest"] = {
      {"method", choice<NestMethod>(nest_methods(), [](auto& c, NestMethod v) { c.nest.method = v; })},
      {"spacing_mm", number(0, false, 1000, "mm", 1, [](auto& c, double v) { c.nest.spacing_mm = v; })},
      {"margin_mm", number(0, false, 1000, "mm", 1, [](auto& c, double v) { c.nest.margin_mm = v; })},
      {"fill_holes", flag([](auto& c, bool v) { c.nest.fill_holes = v; })},
      {"sheet_width_mm", number(0, true, 1e5, "mm", 1, [](auto& c, double v) { c.sheet_width_mm = v; })},
      {"sheet_length_mm", number(0, true, 1e5, "mm", 1, [](auto& c, double v) { c.sheet_length_mm = v; })},
  };
  return s;
}

}  // namespace

std::expected<MachineConfig, Error> parse_machine_toml(std::string_view text_in, const std::string& source) {
  auto parsed = parse_toml(text_in, source);
  if (!parsed) return std::unexpected(parsed.error());
  const toml::table& doc = *parsed;
  MachineConfig c;
  c.head.a_min_rad = -c.head.a_max_rad;
  const auto known = sections();
  for (const auto& [name, node] : doc) {
    const auto sec = known.find(name.str());
    if (sec == known.end()) {
      std::vector<std::string> names;
      for (const auto& [n, _] : known) names.push_back(n);
      return std::unexpected(toml_error(source, name.source(), fmt::format("unknown section [{}] (known: {})", name.str(),
                                                                             fmt::join(names, ", "))));
    }
    const auto* table = node.as_table();
    if (!table) return std::unexpected(toml_error(source, node.source(), fmt::format("{} must be a [{}] table", name.str(), name.str())));
    for (const auto& [key, value] : *table) {
      const auto r = sec->second.find(key.str());
      if (r == sec->second.end()) {
        std::vector<std::string> keys;
        for (const auto& [k, _] : sec->second) keys.push_back(k);
        return std::unexpected(toml_error(source, key.source(), fmt::format("unknown key '{}' in [{}] (known: {})", key.str(),
                                                                              name.str(), fmt::join(keys, ", "))));
      }
      if (auto problem = r->second(value, c))
        return std::unexpected(toml_error(source, value.source(), fmt::format("[{}] {} {}", name.str(), key.str(), *problem)));
    }
  }
  if (c.cutting.feed.min_feed_mm_per_s > c.cutting.feed.max_feed_mm_per_s)
    return std::unexpected(Error{ErrorCode::parse_error, fmt::format("{}: [motion] min_feed_mm_per_min is above max_feed_mm_per_min", source)});
  if (c.head.c_min_rad >= c.head.c_max_rad)
    return std::unexpected(Error{ErrorCode::parse_error, fmt::format("{}: [head] c_min_deg must be below c_max_deg", source)});
  return c;
}

std::expected<MachineConfig, Error> read_machine_file(const std::string& path) {
  auto text = read_config_file(path, "machine");
  if (!text) return std::unexpected(text.error());
  return parse_machine_toml(*text, path);
}

std::string default_config_dir() {
  if (const char* env = std::getenv("LAMINA_CONFIG_DIR"); env && *env) return env;
  return LAMINA_DEFAULT_CONFIG_DIR;
}

}  // namespace lamina::cli
