#pragma once
// A whole program through the simulated controller, as fast as it will go (no ports, no waiting):
// the offline modes' way of cutting (--measure-coupon, --as-cut). Each line is submitted and its
// blocks run to the end before the next line, so a block belongs to the last line before it and
// to the last marker comment read.
#include <cstddef>
#include <expected>
#include <functional>
#include <string>
#include <string_view>

#include "machine.hpp"

namespace lamina::sim {

struct ProgramCallbacks {
  std::function<void(std::string_view line)> on_line;        // before the line is submitted
  std::function<void(const ExecutedBlock& block)> on_block;  // every block the line ran
};

// Errors name the program's line the controller refused.
std::expected<void, std::string> run_program(std::string_view program, MachineConfig machine,
                                             const ProgramCallbacks& callbacks);

// FNV-1a, 64 bits, as 16 hex digits: which program an as-cut record was cut from. Lamina reads it
// with its own copy (daemon/cli/as_cut_files.cpp): the simulator links nothing of Lamina's.
std::string program_fingerprint(std::string_view program);

}  // namespace lamina::sim
