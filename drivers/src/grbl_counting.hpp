#pragma once
// The engine behind make_grbl_protocol and make_send_response_protocol: both speak Grbl's
// line grammar (ok / error:N / ALARM:N); they differ only in how many lines may be in flight.
#include <cstddef>
#include <memory>
#include <string>

#include "lamina/drivers/line_protocol.hpp"

namespace lamina::drivers::detail {

struct CountingSettings {
  std::string name;
  // Character counting: bytes of unacknowledged lines kept within this window. 0: learn it
  // from `[OPT:]` at the handshake, else classic Grbl's 128.
  std::size_t rx_buffer_bytes = 0;
  bool one_line_in_flight = false;  // send-response: wait for each line's answer
  bool read_build_info = true;      // handshake with `$I`
};

std::unique_ptr<LineProtocol> make_counting_protocol(CountingSettings settings);

}  // namespace lamina::drivers::detail
