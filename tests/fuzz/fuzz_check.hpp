#pragma once
// What every reader fuzz target checks beyond "no crash, no sanitizer report, no hang": the
// result is the same with quoting on and off, a soup is whole triangles, an error names the file,
// and an error or note with quoting off holds no 24-byte run of the input.
#include "lamina/core/mesh_io.hpp"

#include <cstdlib>
#include <cstdio>
#include <functional>
#include <string_view>
#include <unordered_set>

namespace lamina::fuzz {

inline constexpr std::string_view kName = "fuzz-input";

inline void require(bool ok, const char* what, std::string_view detail = {}) {
  if (ok) return;
  std::fprintf(stderr, "fuzz check failed: %s: %.*s\n", what, static_cast<int>(detail.size()), detail.data());
  std::abort();
}

// No window of `run` bytes of `input` appears in `text`.
inline bool quotes_nothing(std::string_view text, std::string_view input, std::size_t run = 24) {
  if (text.size() < run || input.size() < run) return true;
  std::unordered_set<std::string_view> windows;
  for (std::size_t i = 0; i + run <= text.size(); ++i) windows.insert(text.substr(i, run));
  for (std::size_t i = 0; i + run <= input.size(); ++i)
    if (windows.count(input.substr(i, run)) != 0) return false;
  return true;
}

using Reader = std::function<std::expected<TriangleSoup, Error>(const MeshReadOptions&)>;

inline void check_reader(const Reader& read, std::string_view input) {
  MeshReadOptions quoting, neutral;
  neutral.quote_file_text = false;
  const auto on = read(quoting);
  const auto off = read(neutral);
  require(on.has_value() == off.has_value(), "quoting changed the outcome");
  if (on) {
    require(!on->corners.empty() && on->corners.size() % 3 == 0, "a soup of whole triangles");
    require(on->corners.size() == off->corners.size(), "quoting changed the soup");
    for (const ReadNote& n : off->notes) require(quotes_nothing(n.message, input), "a note quoted the input", n.message);
    return;
  }
  require(on.error().code == off.error().code, "quoting changed the error code", off.error().message);
  require(off.error().message.starts_with(kName), "an error names the file", off.error().message);
  require(quotes_nothing(off.error().message, input), "an error quoted the input", off.error().message);
}

}  // namespace lamina::fuzz
