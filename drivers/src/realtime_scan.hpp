#pragma once
// The pre-flight check the streaming protocols share: a controller takes some bytes as
// real-time commands the moment they arrive, wherever they stand in a line — inside a comment
// too (grblHAL picks `!` off the wire in its UART interrupt). A program from elsewhere that
// holds one would hold, reset or override the machine mid-cut, so it is refused before anything
// is sent. Refused, not stripped: a streamer that rewrites a program behind the engineer's back
// is worse than one that names the line; Lamina's own posts never write such bytes.
#include <functional>
#include <optional>
#include <string_view>

#include <fmt/format.h>

#include "lamina/drivers/line_protocol.hpp"

namespace lamina::drivers::detail {

// What byte `c` would do to the controller, or nullptr when it is plain text.
using RealtimeMeaning = std::function<const char*(unsigned char c)>;

inline std::optional<LinkError> refuse_realtime_line(std::size_t index, std::string_view line,
                                                     const RealtimeMeaning& meaning, std::string_view controller) {
  for (std::size_t column = 0; column < line.size(); ++column) {
    const auto c = static_cast<unsigned char>(line[column]);
    const char* what = meaning(c);
    if (!what) continue;
    const std::string shown = c >= 0x20 && c < 0x7F ? fmt::format("'{}'", static_cast<char>(c)) : fmt::format("0x{:02X}", c);
    return LinkError{LinkErrorCode::bad_request,
                     fmt::format("line {}, column {}: {} is {} to a {} controller, even inside a comment; remove it "
                                 "from the program (nothing was sent)",
                                 index + 1, column + 1, shown, what, controller)};
  }
  return std::nullopt;
}

}  // namespace lamina::drivers::detail
