#include "stock_config.hpp"

#include <fmt/format.h>
#include "toml_file.hpp"

#include <algorithm>
#include <cmath>
#include <optional>

namespace lamina::cli {
namespace {

constexpr std::string_view kKnownKeys = "thickness_mm, width_mm, length_mm, count, material, slot";
constexpr std::size_t kMaxSlotChars = 40;  // a label on the rack, shown big on the operator's prompt

// A length in mm: a TOML integer or float, finite, >= 0 (> 0 when `positive`).
std::expected<double, Error> length_mm(const std::string& source, std::string_view key, const toml::node& node,
                                       bool positive) {
  std::optional<double> v;
  if (const auto* i = node.as_integer()) v = static_cast<double>(i->get());
  if (const auto* f = node.as_floating_point()) v = f->get();
  if (!v) return std::unexpected(toml_error(source, node.source(), fmt::format("{} must be a number of millimetres", key)));
  if (!std::isfinite(*v) || *v < 0.0 || (positive && *v == 0.0))
    return std::unexpected(
        toml_error(source, node.source(), fmt::format("{} = {} is out of range (must be {} 0)", key, *v, positive ? ">" : ">=")));
  return *v;
}

std::expected<SheetStock, Error> read_sheet(const std::string& source, const toml::table& t) {
  SheetStock s;
  bool has_thickness = false;
  for (const auto& [key, node] : t) {
    const std::string_view k = key.str();
    if (k == "thickness_mm" || k == "width_mm" || k == "length_mm") {
      auto v = length_mm(source, k, node, k == "thickness_mm");
      if (!v) return std::unexpected(v.error());
      (k == "thickness_mm" ? s.thickness_mm : k == "width_mm" ? s.width_mm : s.length_mm) = *v;
      has_thickness = has_thickness || k == "thickness_mm";
    } else if (k == "count") {
      const auto* i = node.as_integer();
      if (!i || i->get() < 0 || i->get() > 1'000'000)
        return std::unexpected(toml_error(source, node.source(), "count must be a whole number of sheets, 0 … 1000000"));
      s.count = static_cast<int>(i->get());
    } else if (k == "material") {
      const auto* m = node.as_string();
      if (!m) return std::unexpected(toml_error(source, node.source(), "material must be a string"));
      s.material = m->get();
    } else if (k == "slot") {
      const auto* slot = node.as_string();
      const bool printable = slot && std::ranges::none_of(slot->get(), [](unsigned char c) { return c < 0x20 || c == 0x7f; });
      if (!slot || slot->get().empty() || slot->get().size() > kMaxSlotChars || !printable)
        return std::unexpected(toml_error(source, node.source(),
                                          fmt::format("slot must be a rack label of 1 … {} printable characters", kMaxSlotChars)));
      s.slot = slot->get();
    } else {
      return std::unexpected(
          toml_error(source, key.source(), fmt::format("unknown key '{}' in [[sheet]] (known: {})", k, kKnownKeys)));
    }
  }
  if (!has_thickness) return std::unexpected(toml_error(source, t.source(), "[[sheet]] without thickness_mm"));
  return s;
}

}  // namespace

std::expected<Stock, Error> parse_stock_toml(std::string_view text, const std::string& source_name) {
  auto parsed = parse_toml(text, source_name);
  if (!parsed) return std::unexpected(parsed.error());
  const toml::table& doc = *parsed;
  Stock stock;
  for (const auto& [key, node] : doc) {
    if (key.str() != "sheet")
      return std::unexpected(toml_error(source_name, key.source(),
                                         fmt::format("unknown key '{}' (the file holds [[sheet]] tables only)", key.str())));
    const auto* sheets = node.as_array();
    if (!sheets || !sheets->is_array_of_tables())
      return std::unexpected(toml_error(source_name, node.source(), "sheet must be written [[sheet]], one table per kind of sheet"));
    for (const toml::node& entry : *sheets) {
      auto sheet = read_sheet(source_name, *entry.as_table());
      if (!sheet) return std::unexpected(sheet.error());
      stock.sheets.push_back(std::move(*sheet));
    }
  }
  if (stock.sheets.empty())
    return std::unexpected(Error{ErrorCode::parse_error, fmt::format("{}: no [[sheet]] in the file", source_name)});
  return stock;
}

std::expected<Stock, Error> read_stock_file(const std::string& path) {
  auto text = read_config_file(path, "stock");
  if (!text) return std::unexpected(text.error());
  return parse_stock_toml(*text, path);
}

Stock sheets_of_unknown_size(std::span<const double> thicknesses_mm) {
  Stock stock;
  for (double t : thicknesses_mm) {
    SheetStock s;
    s.thickness_mm = t;
    stock.sheets.push_back(std::move(s));
  }
  return stock;
}

}  // namespace lamina::cli
