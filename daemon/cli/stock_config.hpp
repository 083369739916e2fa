#pragma once
// The stock file: the shop's rack of sheets as TOML, one [[sheet]] table per kind of sheet.
//
//   [[sheet]]
//   thickness_mm = 2.5          # required, > 0
//   width_mm = 1250             # optional, >= 0 (0: not given)
//   length_mm = 2500            # optional, >= 0
//   count = 8                   # optional whole number >= 0 (0: not given)
//   material = "aluminium 6061" # optional
//
// Any other key is an error naming the key and its line (a typo must not silently drop a field).
#include "lamina/core/error.hpp"
#include "lamina/core/stock.hpp"

#include <expected>
#include <span>
#include <string>
#include <string_view>

namespace lamina::cli {

// Errors: io_error (cannot read), parse_error ("FILE:LINE: what").
std::expected<Stock, Error> read_stock_file(const std::string& path);
std::expected<Stock, Error> parse_stock_toml(std::string_view text, const std::string& source_name);

// Sheets known by thickness only (--stock).
Stock sheets_of_unknown_size(std::span<const double> thicknesses_mm);

}  // namespace lamina::cli
