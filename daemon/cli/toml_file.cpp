#include "toml_file.hpp"

#include <fmt/format.h>

#include <filesystem>
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

// A configuration file is small text: a FIFO or a device (stock_file=/dev/zero grew the planner
// by 1.8 GB in 6 s) is refused before it is read, and so is anything over kMaxConfigBytes.
std::expected<std::string, Error> read_config_file(const std::string& path, std::string_view what) {
  constexpr std::uintmax_t kMaxConfigBytes = 16u << 20;
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (!ec && std::filesystem::exists(status) && !std::filesystem::is_regular_file(status))
    return std::unexpected(Error{ErrorCode::io_error, fmt::format("{} file {} is not a regular file", what, path)});
  if (const auto size = std::filesystem::file_size(path, ec); !ec && size > kMaxConfigBytes)
    return std::unexpected(Error{ErrorCode::io_error, fmt::format("{} file {} is {} bytes; a {} file is at most {}", what,
                                                                  path, size, what, kMaxConfigBytes)});
  std::ifstream in(path, std::ios::binary);
  const auto fail = [&] { return std::unexpected(Error{ErrorCode::io_error, fmt::format("cannot read {} file {}", what, path)}); };
  if (!in) return fail();
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad() || text.tellp() > static_cast<std::streamoff>(kMaxConfigBytes)) return fail();
  return text.str();
}

}  // namespace lamina::cli
