#include "program_run.hpp"

#include <fmt/format.h>

namespace lamina::sim {

std::expected<void, std::string> run_program(std::string_view program, MachineConfig machine,
                                             const ProgramCallbacks& callbacks) {
  machine.planner_blocks = 1u << 20;
  Machine m(machine);
  double now_s = 0.0;
  std::size_t line_no = 0;
  for (std::size_t start = 0; start < program.size();) {
    const std::size_t nl = program.find('\n', start);
    const std::string_view line = program.substr(start, nl == std::string_view::npos ? std::string_view::npos : nl - start);
    start = nl == std::string_view::npos ? program.size() : nl + 1;
    ++line_no;
    if (callbacks.on_line) callbacks.on_line(line);
    if (m.submit_line(line, now_s) != GrblStatus::ok)
      return std::unexpected(fmt::format("line {}: the controller refused '{}'", line_no, line));
    now_s += 1e4;  // longer than any block: the line's blocks have all run before the next line
    m.advance(now_s);
    for (const auto& event : m.take_events())
      if (const auto* b = std::get_if<ExecutedBlock>(&event); b && callbacks.on_block) callbacks.on_block(*b);
  }
  return {};
}

std::string program_fingerprint(std::string_view program) {
  std::uint64_t h = 0xcbf29ce484222325ull;
  for (const char c : program) {
    h ^= static_cast<unsigned char>(c);
    h *= 0x100000001b3ull;
  }
  return fmt::format("{:016x}", h);
}

}  // namespace lamina::sim
