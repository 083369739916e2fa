#pragma once
// Splitting a controller's text reply into its fields (`a,b,c`, `OPT:…`): the parsers of
// grbl_reply.cpp and grbl_status.cpp share it. Views into the caller's string.
#include <string_view>
#include <vector>

namespace lamina::drivers {

// "a,,b" → {"a", "", "b"}; "" → {""}.
inline std::vector<std::string_view> split_fields(std::string_view s, char separator) {
  std::vector<std::string_view> parts;
  for (;;) {
    const auto at = s.find(separator);
    parts.push_back(s.substr(0, at));
    if (at == std::string_view::npos) return parts;
    s.remove_prefix(at + 1);
  }
}

}  // namespace lamina::drivers
