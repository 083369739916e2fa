// Grbl / grblHAL character counting: the window is the controller's receive buffer, read
// from `[OPT:]` by the `$I` handshake unless configured.
#include "grbl_counting.hpp"

namespace lamina::drivers {

std::unique_ptr<LineProtocol> make_grbl_protocol(GrblProtocolSettings settings) {
  return detail::make_counting_protocol(
      {.name = "grbl", .rx_buffer_bytes = settings.rx_buffer_bytes, .one_line_in_flight = false,
       .read_build_info = true});
}

}  // namespace lamina::drivers
