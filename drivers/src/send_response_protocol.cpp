// Send-response: one line in flight, the next only after its ok. Slow (a round trip per
// line) but needs no buffer size: for settings, and for controllers that do not report one.
// No handshake: it must work with a controller that knows no `$I`.
#include "grbl_counting.hpp"

namespace lamina::drivers {

std::unique_ptr<LineProtocol> make_send_response_protocol() {
  return detail::make_counting_protocol(
      {.name = "send-response", .rx_buffer_bytes = 0, .one_line_in_flight = true, .read_build_info = false});
}

}  // namespace lamina::drivers
