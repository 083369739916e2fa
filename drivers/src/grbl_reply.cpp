#include "grbl_reply.hpp"

#include <charconv>
#include <utility>

#include "grbl_codes.hpp"
#include "text_fields.hpp"

namespace lamina::drivers::detail {
namespace {

// A line longer than this without an end is not a reply (grblHAL's longest are a few hundred
// bytes); hand it on so it is reported as garbage instead of growing without bound.
constexpr std::size_t kMaxReplyBytes = 1024;

bool starts_with(std::string_view s, std::string_view prefix) { return s.substr(0, prefix.size()) == prefix; }

std::optional<int> to_int(std::string_view s) {
  int value = 0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), value);
  if (ec != std::errc() || end != s.data() + s.size() || s.empty()) return std::nullopt;
  return value;
}

// `error:20` / `ALARM:2`: the number, or 0 with the text kept in the line (Grbl 0.9 sent words).
Reply numbered(ReplyKind kind, std::string_view line, std::size_t prefix) {
  return Reply{kind, to_int(line.substr(prefix)).value_or(0), std::string(line)};
}

}  // namespace

std::vector<std::string> ReplyLineSplitter::feed(std::string_view bytes) {
  std::vector<std::string> lines;
  for (const char c : bytes) {
    if (c == '\n') {
      if (!partial_.empty() && partial_.back() == '\r') partial_.pop_back();
      if (!partial_.empty()) lines.push_back(std::move(partial_));  // blank lines carry nothing
      partial_.clear();
    } else {
      partial_.push_back(c);
      if (partial_.size() >= kMaxReplyBytes) lines.push_back(std::exchange(partial_, {}));
    }
  }
  return lines;
}

Reply classify_reply(std::string_view line) {
  if (line == "ok") return Reply{ReplyKind::ok, 0, std::string(line)};
  if (starts_with(line, "error:")) return numbered(ReplyKind::error, line, 6);
  if (starts_with(line, "ALARM:")) return numbered(ReplyKind::alarm, line, 6);
  if (starts_with(line, "Grbl")) return Reply{ReplyKind::banner, 0, std::string(line)};  // also "GrblHAL"
  if (starts_with(line, "<") && line.back() == '>') return Reply{ReplyKind::status, 0, std::string(line)};
  if (starts_with(line, "[") || starts_with(line, "$") || starts_with(line, ">"))
    return Reply{ReplyKind::info, 0, std::string(line)};
  return Reply{ReplyKind::unknown, 0, std::string(line)};
}

bool learn_build_info(std::string_view line, ControllerInfo& info) {
  if (line.size() < 2 || line.front() != '[' || line.back() != ']') return false;
  const std::string_view body = line.substr(1, line.size() - 2);
  if (starts_with(body, "OPT:")) {
    // Grbl 1.1: [OPT:V,15,128]; grblHAL adds the axis count and more after the rx size.
    const auto fields = split_fields(body.substr(4), ',');
    if (fields.size() > 1) info.planner_blocks = to_int(fields[1]);
    if (fields.size() > 2) info.rx_buffer_bytes = to_int(fields[2]);
    if (fields.size() > 3) info.axes = to_int(fields[3]);
    return true;
  }
  if (starts_with(body, "AXS:")) {  // grblHAL: [AXS:5:XYZAC]
    const auto fields = split_fields(body.substr(4), ':');
    if (auto n = to_int(fields[0])) info.axes = n;
    if (fields.size() > 1) info.axis_letters = std::string(fields[1]);
    return true;
  }
  return false;
}

std::string error_meaning(const Reply& reply) {
  return reply.code ? grbl_error_meaning(reply.code) : reply.line.substr(6);
}
std::string alarm_meaning(const Reply& reply) {
  return reply.code ? grbl_alarm_meaning(reply.code) : reply.line.substr(6);
}

}  // namespace lamina::drivers::detail
