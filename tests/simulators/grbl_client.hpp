#pragma once
// The tests' own character-counting sender (the Grbl wiki's streaming scheme, written here
// from the protocol description, independent of drivers/): keep the controller's receive
// buffer full, never overfull, and count its answers.
#include <cmath>
#include <deque>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "sim_process.hpp"

namespace lamina::sim::testing {

struct StreamResult {
  std::size_t oks = 0;
  std::vector<std::string> errors;  // "error:N" lines in order
  std::vector<std::string> alarms;  // "ALARM:N"
  double seconds = 0;
  bool finished = false;
};

// What grblHAL's 1024-byte receive ring holds: one slot stays free to tell full from empty, so
// Bf reports 1023 free at most (while $I's [OPT:] names 1024). A sender that fills 1024 loses a byte.
inline constexpr std::size_t kGrblHalRxBytes = 1023;

// Send `lines` with at most `rx_bytes` unacknowledged bytes in flight. Stops on an alarm, on
// a closed link, or after `timeout_s`.
inline StreamResult stream_counting(StreamClient& link, const std::vector<std::string>& lines, std::size_t rx_bytes,
                                    double timeout_s) {
  StreamResult r;
  std::deque<std::size_t> in_flight;
  std::size_t in_flight_bytes = 0, next = 0, parsed = 0;
  const auto t0 = std::chrono::steady_clock::now();
  while (r.oks + r.errors.size() < lines.size() && seconds_since(t0) < timeout_s && r.alarms.empty()) {
    while (next < lines.size() && in_flight_bytes + lines[next].size() + 1 <= rx_bytes) {
      if (!link.send(lines[next] + "\n")) break;
      in_flight.push_back(lines[next].size() + 1);
      in_flight_bytes += lines[next].size() + 1;
      ++next;
    }
    link.read_until([&](const std::string& b) { return b.find('\n', parsed) != std::string::npos; }, 0.05);
    if (link.closed()) break;
    for (std::size_t eol; (eol = link.buffer().find('\n', parsed)) != std::string::npos; parsed = eol + 1) {
      std::string reply = link.buffer().substr(parsed, eol - parsed);
      if (!reply.empty() && reply.back() == '\r') reply.pop_back();
      const bool ack = reply == "ok" || reply.rfind("error:", 0) == 0;
      if (reply == "ok") ++r.oks;
      if (reply.rfind("error:", 0) == 0) r.errors.push_back(reply);
      if (reply.rfind("ALARM:", 0) == 0) r.alarms.push_back(reply);
      if (ack && !in_flight.empty()) {
        in_flight_bytes -= in_flight.front();
        in_flight.pop_front();
      }
    }
  }
  r.seconds = seconds_since(t0);
  r.finished = r.oks + r.errors.size() == lines.size();
  return r;
}

// A 5-axis cutting program of `moves` short moves, inside the default soft limits: G94
// linear moves and G93 inverse-time moves that turn the head, jet on and off.
inline std::vector<std::string> five_axis_program(std::size_t moves, double step_mm = 0.5) {
  std::vector<std::string> p{"G21G90G94", "(CONTOUR 1 L1-1 OUTLINE 1 PASS 1)", "G0X10Y10Z5", "M3", "G1Z0F900"};
  for (std::size_t i = 0; i < moves; ++i) {
    const double x = 10 + step_mm * static_cast<double>(i);
    const double y = 10 + 5 * std::sin(static_cast<double>(i) * 0.05);
    if (i % 2 == 0) {
      p.push_back(fmt::format("G1X{:.3f}Y{:.3f}F1800", x, y));
    } else {
      const double a = 20 * std::sin(static_cast<double>(i) * 0.01);
      const double c = 0.5 * static_cast<double>(i);
      p.push_back(fmt::format("G93G1X{:.3f}Y{:.3f}A{:.3f}C{:.3f}F{:.1f}", x, y, a, c, 3600.0));
      p.push_back("G94");
    }
  }
  p.insert(p.end(), {"M5", "G0Z5", "M30"});
  return p;
}

}  // namespace lamina::sim::testing
