#pragma once
// What every config loader (stock, materials, machine) does the same way: read the file, parse
// it with toml++, and word errors as "FILE:LINE: what".
#include "lamina/core/error.hpp"

#include <toml++/toml.h>

#include <expected>
#include <string>
#include <string_view>

namespace lamina::cli {

// parse_error "SOURCE:LINE: what", the line where `where` begins.
Error toml_error(const std::string& source, const toml::source_region& where, const std::string& what);

// The document, or toml++'s own message at its line.
std::expected<toml::table, Error> parse_toml(std::string_view text, const std::string& source);

// The whole file; io_error "cannot read <what> file PATH" when it cannot be opened or read.
std::expected<std::string, Error> read_config_file(const std::string& path, std::string_view what);

}  // namespace lamina::cli
