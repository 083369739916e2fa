#pragma once
// grblHAL-like personality: character-counting line protocol, `ok` / `error:N`, the error
// lock, ALARM:N, $ commands ($I build info with [OPT:] and [AXS:], $X, $$ …) and the
// real-time bytes ? ! ~ 0x18 outside the line buffer.
#include <memory>

#include "cnc_protocol.hpp"

namespace lamina::sim {

struct GrblParams {
  std::size_t rx_buffer_bytes = 1024;  // 128 for classic Grbl
  ProtocolFaults faults;
};

std::unique_ptr<CncProtocol> make_grbl_protocol(Machine& machine, GrblParams params);

}  // namespace lamina::sim
