#pragma once
// Drives a CncProtocol and a real Machine with a simulated clock, the way the process loop
// does: bytes one at a time, then machine.advance + protocol.poll. Output is collected so a
// test can look at everything the controller said since the last `take()`.
#include <algorithm>
#include <memory>
#include <string>
#include <string_view>
#include <utility>
#include <variant>
#include <vector>

#include "cnc_protocol.hpp"
#include "machine.hpp"

namespace lamina::sim::test {

struct ProtocolHarness {
  explicit ProtocolHarness(MachineConfig config) : machine(std::move(config)) {}

  // Every byte arrives at the current time; the protocol is polled after each, as a fast
  // process loop would.
  void send(std::string_view bytes) {
    for (char c : bytes) {
      protocol->on_byte(static_cast<std::uint8_t>(c), now_s);
      tick();
    }
  }
  // Bytes arrive with no poll in between (a burst faster than the loop drains).
  void send_burst(std::string_view bytes) {
    for (char c : bytes) protocol->on_byte(static_cast<std::uint8_t>(c), now_s);
  }
  void tick() {
    machine.advance(now_s);
    protocol->poll(now_s);
    take_output();
  }
  // Advance the clock in small steps so the protocol sees the machine's progress.
  void run_for(double seconds, double step_s = 0.01) {
    const double end = now_s + seconds;
    while (now_s + 1e-12 < end) {
      now_s = std::min(end, now_s + step_s);
      tick();
    }
  }
  std::string take() {
    take_output();
    return std::exchange(output, {});
  }
  // What the controller says crosses at once (a wire with no delay).
  void take_output() {
    const std::string said = protocol->take_output();
    protocol->on_output_sent(said.size());
    output += said;
  }
  // Lines of the executed blocks so far (consumes the machine's events, which only the
  // process loop does in the program; the protocols never read them).
  std::vector<std::string> executed_lines() {
    for (const MachineEvent& e : machine.take_events())
      if (const auto* block = std::get_if<ExecutedBlock>(&e)) executed.push_back(block->line);
    return executed;
  }

  Machine machine;
  std::unique_ptr<CncProtocol> protocol;
  double now_s = 0;
  std::string output;
  std::vector<std::string> executed;
};

inline int count_of(std::string_view text, std::string_view what) {
  int n = 0;
  for (std::size_t pos = text.find(what); pos != std::string_view::npos; pos = text.find(what, pos + what.size()))
    ++n;
  return n;
}

}  // namespace lamina::sim::test
