// Grbl 1.1 / grblHAL real-time status report (Grbl wiki "Interface", "Real-time Status
// Reports"): `<State|Field:values|…>`, fields in no promised order, any of them optional.
// Positions are taken in millimetres and degrees: lamina configures `$13=0` (report in mm).
#include <array>
#include <charconv>
#include <vector>

#include "lamina/drivers/controller_status.hpp"
#include "text_fields.hpp"

namespace lamina::drivers {
namespace {

// Our machine is XYZAC: a report with another axis count cannot be mapped onto it.
constexpr std::size_t kMachineAxes = 5;
constexpr double kSecondsPerMinute = 60.0;

template <typename T>
std::optional<T> number(std::string_view s) {
  T value{};
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), value);
  if (s.empty() || ec != std::errc() || end != s.data() + s.size()) return std::nullopt;
  return value;
}

// "x,y,z[,a[,b[,c]]]": Grbl reports 3 axes, grblHAL up to 6 (8 with options).
std::optional<std::vector<double>> axes(std::string_view s) {
  std::vector<double> values;
  for (const auto part : split_fields(s, ',')) {
    const auto v = number<double>(part);
    if (!v) return std::nullopt;
    values.push_back(*v);
  }
  if (values.size() < 3 || values.size() > 8) return std::nullopt;
  return values;
}

std::optional<ControllerState> state_of(std::string_view word, std::string_view sub) {
  if (word == "Idle") return ControllerState::idle;
  if (word == "Run") return ControllerState::run;
  // Hold:0 the hold is complete (stopped, may resume); Hold:1 still decelerating. A bare or
  // unknown sub-state is taken as still in progress: nothing may assume it stopped.
  if (word == "Hold") return sub.empty() || sub == "0" ? ControllerState::hold : ControllerState::hold_pending;
  if (word == "Alarm") return ControllerState::alarm;
  if (word == "Door") return ControllerState::door;  // Door:0..3, all mean the door holds the machine
  if (word == "Check") return ControllerState::check;
  if (word == "Home") return ControllerState::home;
  if (word == "Sleep") return ControllerState::sleep;
  if (word == "Jog") return ControllerState::jog;
  if (word == "Tool") return ControllerState::tool;  // grblHAL: tool change pending
  return std::nullopt;
}

std::optional<std::array<double, kMachineAxes>> machine_axes(const std::vector<double>& v) {
  if (v.size() != kMachineAxes) return std::nullopt;
  std::array<double, kMachineAxes> out{};
  for (std::size_t i = 0; i < kMachineAxes; ++i) out[i] = v[i];
  return out;
}

}  // namespace

std::optional<ControllerStatus> parse_grbl_status(std::string_view report) {
  const bool opens = !report.empty() && report.front() == '<';
  const bool closes = !report.empty() && report.back() == '>';
  if (opens != closes) return std::nullopt;  // cut off: half a report is not a report
  if (opens) report = report.substr(1, report.size() - 2);

  const auto fields = split_fields(report, '|');
  if (fields[0].empty()) return std::nullopt;
  ControllerStatus status;
  status.state_text = std::string(fields[0]);
  {
    const auto colon = fields[0].find(':');
    const auto word = fields[0].substr(0, colon);
    const auto sub = colon == std::string_view::npos ? std::string_view() : fields[0].substr(colon + 1);
    // A state word we do not know is reported as unknown, not as garbage: grblHAL adds states.
    status.state = state_of(word, sub).value_or(ControllerState::unknown);
  }

  std::optional<std::vector<double>> mpos, wpos, wco;
  for (std::size_t i = 1; i < fields.size(); ++i) {
    const auto colon = fields[i].find(':');
    if (colon == std::string_view::npos) continue;  // a flag field of a newer grblHAL
    const auto key = fields[i].substr(0, colon);
    const auto value = fields[i].substr(colon + 1);
    if (key == "MPos" || key == "WPos" || key == "WCO") {
      auto v = axes(value);
      if (!v) return std::nullopt;
      (key == "MPos" ? mpos : key == "WPos" ? wpos : wco) = std::move(v);
    } else if (key == "Bf") {
      const auto parts = split_fields(value, ',');
      if (parts.size() != 2) return std::nullopt;
      status.planner_blocks_free = number<int>(parts[0]);
      status.rx_bytes_free = number<int>(parts[1]);
      if (!status.planner_blocks_free || !status.rx_bytes_free) return std::nullopt;
    } else if (key == "Ln") {
      status.line_number = number<std::int64_t>(value);
      if (!status.line_number) return std::nullopt;
    } else if (key == "FS" || key == "F") {
      const auto feed_mm_per_min = number<double>(split_fields(value, ',')[0]);
      if (!feed_mm_per_min) return std::nullopt;
      status.feed_mm_per_s = *feed_mm_per_min / kSecondsPerMinute;
    }
    // Pn, Ov, A, and grblHAL's additions (SD, H, T, MPG…) carry nothing the link acts on.
  }

  if (mpos) {
    status.machine_position = machine_axes(*mpos);
  } else if (wpos) {
    // WPos only when $10 asks for work positions: machine = work + WCO. WCO is sent every
    // 10–30 reports, so without it in this report the work position is taken as is — exact
    // only while the work offset is zero (lamina sets $10 so that MPos is reported).
    auto machine = *wpos;
    if (wco && wco->size() == wpos->size())
      for (std::size_t i = 0; i < machine.size(); ++i) machine[i] += (*wco)[i];
    status.machine_position = machine_axes(machine);
  }
  return status;
}

const char* to_string(ControllerState state) {
  switch (state) {
    case ControllerState::unknown: return "unknown";
    case ControllerState::idle: return "idle";
    case ControllerState::run: return "run";
    case ControllerState::hold_pending: return "hold_pending";
    case ControllerState::hold: return "hold";
    case ControllerState::alarm: return "alarm";
    case ControllerState::door: return "door";
    case ControllerState::check: return "check";
    case ControllerState::home: return "home";
    case ControllerState::sleep: return "sleep";
    case ControllerState::jog: return "jog";
    case ControllerState::tool: return "tool";
  }
  return "unknown";
}

}  // namespace lamina::drivers
