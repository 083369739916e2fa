#pragma once
// Scripting a controller for the sans-IO line protocols: feed replies byte by byte, pick
// events of one kind, make programs of a given line length.
#include <algorithm>
#include <string>
#include <string_view>
#include <vector>

#include "lamina/drivers/line_protocol.hpp"

namespace lamina::drivers::script {

using Events = std::vector<ProtocolEvent>;

// Feeds the bytes one at a time, as the slowest serial read would deliver them.
inline Events feed_bytewise(LineProtocol& p, std::string_view bytes) {
  Events all;
  for (const char c : bytes) {
    auto events = p.on_received(std::string_view(&c, 1));
    all.insert(all.end(), events.begin(), events.end());
  }
  return all;
}

template <typename T>
std::vector<T> only(const Events& events) {
  std::vector<T> out;
  for (const auto& e : events)
    if (const auto* t = std::get_if<T>(&e)) out.push_back(*t);
  return out;
}

inline LineSpan program(std::size_t n, std::size_t bytes_per_line, std::size_t first_index = 0) {
  LineSpan span;
  span.first_index = first_index;
  for (std::size_t i = 0; i < n; ++i) {
    std::string line = "G1X" + std::to_string(i);
    line.resize(bytes_per_line, '0');  // padding digits keep it G-code
    span.lines.push_back(line);
  }
  return span;
}

inline std::size_t count_lines(const std::string& bytes) { return static_cast<std::size_t>(std::ranges::count(bytes, '\n')); }

}  // namespace lamina::drivers::script
