#include "sim_options.hpp"

#include <stdexcept>

#include <fmt/format.h>

#include <cmath>
#include <toml++/toml.h>

namespace lamina::sim {
namespace {

std::string where(const std::string& path, const toml::node& node) {
  return fmt::format("{}:{}", path, node.source().begin.line);
}

AxisValues read_axes(const std::string& path, const std::string& key, const toml::node& node) {
  const auto* array = node.as_array();
  if (!array || array->size() != kAxisCount)
    throw std::runtime_error(fmt::format("{}: {} must be an array of 5 numbers (X Y Z A C)", where(path, node), key));
  AxisValues out{};
  for (int i = 0; i < kAxisCount; ++i) {
    const auto value = (*array)[static_cast<std::size_t>(i)].value<double>();
    if (!value) throw std::runtime_error(fmt::format("{}: {}[{}] is not a number", where(path, node), key, i));
    out[static_cast<std::size_t>(i)] = *value;
  }
  return out;
}

double read_positive(const std::string& path, const std::string& key, const toml::node& node) {
  const auto value = node.value<double>();
  if (!value || !(*value > 0))
    throw std::runtime_error(fmt::format("{}: {} must be a positive number", where(path, node), key));
  return *value;
}

std::vector<int> read_codes(const std::string& path, const std::string& key, const toml::node& node) {
  const auto* array = node.as_array();
  if (!array || array->empty())
    throw std::runtime_error(fmt::format("{}: {} must be a non-empty array of M numbers", where(path, node), key));
  std::vector<int> out;
  for (const auto& item : *array) {
    const auto value = item.value<int64_t>();
    if (!value || *value < 0 || *value > 999)
      throw std::runtime_error(fmt::format("{}: {} holds something that is not an M number", where(path, node), key));
    out.push_back(static_cast<int>(*value));
  }
  return out;
}

// One jet_* key: the jet's physics, every coefficient a number > 0 (the taper's offset >= 0).
void read_jet(const std::string& path, const std::string& key, const toml::node& node, JetPhysics& jet) {
  const std::pair<std::string_view, double JetPhysics::*> keys[] = {
      {"jet_separation_mm_per_s_at_10mm", &JetPhysics::separation_mm_per_s_at_10mm},
      {"jet_separation_exponent", &JetPhysics::separation_exponent}, {"jet_focus_mm", &JetPhysics::focus_mm},
      {"jet_slow_widening", &JetPhysics::slow_widening}, {"jet_slow_scale", &JetPhysics::slow_scale},
      {"jet_taper_gain", &JetPhysics::taper_gain}, {"jet_taper_exponent", &JetPhysics::taper_exponent},
      {"jet_taper_offset", &JetPhysics::taper_offset}, {"jet_lag_max_deg", &JetPhysics::lag_max_deg},
      {"jet_lag_rate", &JetPhysics::lag_rate}};
  for (const auto& [name, field] : keys) {
    if (key != name) continue;
    const auto v = node.value<double>();
    const bool zero_ok = name == "jet_taper_offset";
    if (!v || !std::isfinite(*v) || *v < 0 || (*v == 0 && !zero_ok))
      throw std::runtime_error(fmt::format("{}: {} must be a number > 0{}", where(path, node), key, zero_ok ? " (or 0)" : ""));
    jet.*field = *v;
    return;
  }
  std::string known;
  for (const auto& [name, field] : keys) known += std::string(known.empty() ? "" : " ") + std::string(name);
  throw std::runtime_error(fmt::format("{}: unknown key '{}' (the jet's: {})", where(path, node), key, known));
}

// One head_* key into the head (made on the first of them; the others keep their defaults).
void read_head(const std::string& path, const std::string& key, const toml::node& node, HeadGeometry& head) {
  const auto number = node.value<double>();
  if (key == "head_pivot_mm" && number && *number >= 0) head.pivot_mm = *number;
  else if ((key == "head_a_sign" || key == "head_c_sign") && number && (*number == 1 || *number == -1))
    (key == "head_a_sign" ? head.a_sign : head.c_sign) = static_cast<int>(*number);
  else if (key == "head_c_offset_deg" && number && std::abs(*number) <= 360) head.c_offset_deg = *number;
  else if (key == "head_rtcp" && node.value<bool>()) head.rtcp = *node.value<bool>();
  else
    throw std::runtime_error(fmt::format("{}: {} is not one of head_pivot_mm (>= 0), head_a_sign / head_c_sign (1 or -1), "
                                         "head_c_offset_deg (-360 … 360), head_rtcp (true/false) with its value",
                                         where(path, node), key));
}

}  // namespace

void apply_machine_file(const std::string& path, SimOptions& options) {
  toml::table table;
  try {
    table = toml::parse_file(path);
  } catch (const toml::parse_error& e) {
    throw std::runtime_error(fmt::format("{}:{}: {}", path, e.source().begin.line, e.description()));
  }
  auto& m = options.machine;
  for (const auto& [key_node, node] : table) {
    const std::string key(key_node.str());
    if (key == "soft_min") m.soft_min = read_axes(path, key, node);
    else if (key == "soft_max") m.soft_max = read_axes(path, key, node);
    else if (key == "g28_position") m.g28_position = read_axes(path, key, node);
    else if (key == "soft_limits") {
      const auto v = node.value<bool>();
      if (!v) throw std::runtime_error(fmt::format("{}: soft_limits must be true or false", where(path, node)));
      m.soft_limits = *v;
    } else if (key == "rapid_per_min") m.rapid_per_min = read_axes(path, key, node);
    else if (key == "max_feed_mm_per_min") m.max_feed_mm_per_min = read_positive(path, key, node);
    else if (key == "hold_decel_mm_per_s2") m.hold_decel_mm_per_s2 = read_positive(path, key, node);
    else if (key == "planner_blocks") m.planner_blocks = static_cast<std::size_t>(read_positive(path, key, node));
    else if (key == "rx_buffer") {
      const auto bytes = static_cast<std::size_t>(read_positive(path, key, node));
      options.grbl.rx_buffer_bytes = bytes;
      options.xonxoff.buffer_bytes = bytes;
    } else if (key == "jet_on_mcodes") m.parse.jet_on_mcodes = read_codes(path, key, node);
    else if (key == "jet_off_mcodes") m.parse.jet_off_mcodes = read_codes(path, key, node);
    else if (key == "pressure_ramp_s") options.plc.pressure_ramp_s = read_positive(path, key, node);
    else if (key.starts_with("jet_")) read_jet(path, key, node, options.jet);
    else if (key.starts_with("head_")) read_head(path, key, node, options.head ? *options.head : options.head.emplace());
    else
      throw std::runtime_error(fmt::format("{}: unknown key '{}' (known: soft_min soft_max g28_position soft_limits "
                                           "rapid_per_min max_feed_mm_per_min hold_decel_mm_per_s2 "
                                           "planner_blocks rx_buffer jet_on_mcodes jet_off_mcodes pressure_ramp_s "
                                           "head_pivot_mm head_a_sign head_c_sign head_c_offset_deg head_rtcp jet_*)",
                                           where(path, node), key));
  }
  for (int i = 0; i < kAxisCount; ++i)
    if (!(m.soft_min[static_cast<std::size_t>(i)] < m.soft_max[static_cast<std::size_t>(i)]))
      throw std::runtime_error(fmt::format("{}: soft_min of {} is not below soft_max", path, kAxisLetters[static_cast<std::size_t>(i)]));
}

}  // namespace lamina::sim
