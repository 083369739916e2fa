#pragma once
// Fanuc-style drip feed (remote buffer, protocol B): a `%`-framed program, no per-line acks,
// DC3 (0x13) when the buffer passes the high-water mark, DC1 (0x11) when it drains below the
// low-water mark; DC3 + SYN (0x16) on reset, DC3 + NAK (0x15) on alarm. Bytes that arrive while
// in DC3 beyond `overrun_margin_bytes` are lost and raise an overflow alarm.
#include <memory>

#include "cnc_protocol.hpp"

namespace lamina::sim {

struct XonXoffParams {
  std::size_t buffer_bytes = 1024;
  std::size_t high_water_bytes = 768;   // send DC3 when the buffer holds more
  std::size_t low_water_bytes = 256;    // send DC1 when it holds less (after a DC3)
  std::size_t overrun_margin_bytes = 64;  // tolerated after DC3 before the overflow alarm
  ProtocolFaults faults;
};

std::unique_ptr<CncProtocol> make_xonxoff_protocol(Machine& machine, XonXoffParams params);

}  // namespace lamina::sim
