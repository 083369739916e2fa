#include "toml_file.hpp"

#include <fmt/format.h>

#include <fstream>
#include <sstream>

namespace lamina::cli {

Error toml_error(const std::string& source, const toml::source_region& where, const std::string& what) {
  return {ErrorCode::parse_error, fmt::format("{}:{}: {}", source, where.begin.line, what)};
}

std::expected<toml::table, Error> parse_toml(std::string_view text, const std::string& source) {
  try {
    return toml::parse(text, source);
  } catch (const toml::parse_error& e) {
    return std::unexpected(toml_error(source, e.source(), std::string(e.description())));
  }
}

std::expected<std::string, Error> read_config_file(const std::string& path, std::string_view what) {
  std::ifstream in(path, std::ios::binary);
  const auto fail = [&] { return std::unexpected(Error{ErrorCode::io_error, fmt::format("cannot read {} file {}", what, path)}); };
  if (!in) return fail();
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) return fail();
  return text.str();
}

}  // namespace lamina::cli
