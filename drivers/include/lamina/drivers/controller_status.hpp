#pragma once
// What a controller reports about itself (Grbl `?` report, or the PLC's registers for a
// Modbus-fed controller), in SI units.
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace lamina::drivers {

enum class ControllerState { unknown, idle, run, hold_pending, hold, alarm, door, check, home, sleep, jog, tool };

struct ControllerStatus {
  ControllerState state = ControllerState::unknown;
  std::string state_text;                       // as reported: "Hold:0", "Alarm"
  std::optional<std::array<double, 5>> machine_position;  // X Y Z mm, A C deg
  std::optional<int> planner_blocks_free;       // Bf: first field
  std::optional<int> rx_bytes_free;             // Bf: second field
  std::optional<std::int64_t> line_number;      // Ln:
  std::optional<double> feed_mm_per_s;          // FS: first field, converted from mm/min once
  std::optional<std::uint64_t> executed_blocks; // blocks the controller finished (Modbus: executed_high/low)
};

// Parse a Grbl / grblHAL real-time report `<Idle|MPos:…|Bf:…|Ln:…|FS:…>` (with or without the
// chevrons; unknown fields ignored, as grblHAL adds fields over time). nullopt if malformed.
std::optional<ControllerStatus> parse_grbl_status(std::string_view report);

const char* to_string(ControllerState state);

}  // namespace lamina::drivers
