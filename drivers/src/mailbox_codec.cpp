#include "mailbox_codec.hpp"

#include <string>

#include <fmt/format.h>

#include "plc_map.hpp"

namespace lamina::drivers {
namespace pm = plc_map;

std::string describe_line(std::size_t index, std::string_view line) {
  const std::size_t number = index + 1;
  if (line.size() > 60) return fmt::format("line {} '{}…' ({} characters)", number, line.substr(0, 60), line.size());
  return fmt::format("line {} '{}'", number, line);
}

std::optional<LinkError> check_mailbox_block(std::size_t index, std::string_view line) {
  if (line.size() > static_cast<std::size_t>(pm::kMailboxMaxChars))
    return LinkError{LinkErrorCode::bad_request,
                     fmt::format("{} is longer than the mailbox's {} characters", describe_line(index, line),
                                 pm::kMailboxMaxChars)};
  for (const char ch : line) {
    const auto c = static_cast<unsigned char>(ch);
    if ((c < 0x20 && c != '\t') || c == 0x7F)
      return LinkError{LinkErrorCode::bad_request,
                       fmt::format("{} holds control character 0x{:02X}; one block is one line",
                                   describe_line(index, line), c)};
  }
  return std::nullopt;
}

std::vector<std::uint16_t> encode_mailbox_block(std::uint16_t seq, std::string_view line) {
  std::vector<std::uint16_t> regs{seq, static_cast<std::uint16_t>(line.size())};
  for (std::size_t i = 0; i < line.size(); i += 2) {
    const auto high = static_cast<unsigned char>(line[i]);
    const auto low = i + 1 < line.size() ? static_cast<unsigned char>(line[i + 1]) : 0;
    regs.push_back(static_cast<std::uint16_t>(high << 8 | low));
  }
  return regs;
}

ControllerStatus decode_cnc_status(std::span<const std::uint16_t> r) {
  auto u32 = [&](int high) { return static_cast<std::uint32_t>(r[high]) << 16 | r[high + 1]; };
  ControllerStatus s;
  static constexpr ControllerState kStates[] = {ControllerState::idle, ControllerState::run,
                                                ControllerState::hold_pending, ControllerState::hold,
                                                ControllerState::alarm};
  static constexpr const char* kNames[] = {"Idle", "Run", "Hold:1", "Hold:0", "Alarm"};  // as Grbl reports them
  const int code = r[pm::kInCncState];
  s.state = code < 5 ? kStates[code] : ControllerState::unknown;
  s.state_text = code < 5 ? kNames[code] : fmt::format("cnc_state {}", code);
  s.executed_blocks = u32(pm::kInExecutedHigh);
  s.planner_blocks_free = r[pm::kInMailboxFree];
  std::array<double, 5> position{};
  for (int axis = 0; axis < 5; ++axis)  // µm → mm, millidegree → degree
    position[static_cast<std::size_t>(axis)] = static_cast<std::int32_t>(u32(pm::kInPositionFirst + 2 * axis)) / 1000.0;
  s.machine_position = position;
  return s;
}

}  // namespace lamina::drivers
