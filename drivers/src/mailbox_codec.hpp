#pragma once
// The PLC's G-code block mailbox and CNC registers as data (docs/modbus-map.md, "Block
// mailbox"): checking and encoding a block, counting sequence numbers, decoding the CNC status.
// Pure: no I/O, so the encoding is tested byte for byte.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string_view>
#include <vector>

#include "lamina/drivers/controller_status.hpp"
#include "lamina/drivers/link_error.hpp"

namespace lamina::drivers {

// A line the mailbox cannot carry (longer than 200 characters, or a control character other
// than tab that the PLC would refuse): bad_request naming the program index, before anything is sent.
std::optional<LinkError> check_mailbox_block(std::size_t index, std::string_view line);

// The registers of one FC16 write at mailbox_seq (10): seq, length, text two characters per
// register, high byte first (an odd last character in the high byte).
std::vector<std::uint16_t> encode_mailbox_block(std::uint16_t seq, std::string_view line);

// 1, 2, … 65535, 1: 0 is the PLC's power-on value and never used.
inline std::uint16_t next_mailbox_seq(std::uint16_t seq) { return seq >= 65535 ? 1 : static_cast<std::uint16_t>(seq + 1); }

// The CNC part of the input registers 0…19: state, executed blocks, positions (µm and
// millidegrees converted to mm and degrees here), free planner blocks.
ControllerStatus decode_cnc_status(std::span<const std::uint16_t> input_registers);

// "line 13 'G1X10'" for the program's index 12: how errors name a line, counted from 1 as the
// program's lines are (an editor's, the contour markers', the serial streamer's) and long lines
// shortened. (It said the 0-based index: an operator looked one line too early.)
std::string describe_line(std::size_t index, std::string_view line);

}  // namespace lamina::drivers
