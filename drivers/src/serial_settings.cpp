#include "serial_settings.hpp"

#include <fmt/core.h>

namespace lamina::drivers::detail {

std::expected<void, LinkError> validate(const SerialSettings& s, const std::string& port) {
  if (s.baud <= 0)
    return std::unexpected(LinkError{LinkErrorCode::bad_request, fmt::format("{}: baud {} is not a baud rate", port, s.baud)});
  if (s.data_bits < 5 || s.data_bits > 8)
    return std::unexpected(
        LinkError{LinkErrorCode::bad_request, fmt::format("{}: data bits {} (a UART takes 5 to 8)", port, s.data_bits)});
  if (s.stop_bits != 1 && s.stop_bits != 2)
    return std::unexpected(
        LinkError{LinkErrorCode::bad_request, fmt::format("{}: stop bits {} (1 or 2)", port, s.stop_bits)});
  return {};
}

const char* flow_text(FlowControl flow) {
  switch (flow) {
    case FlowControl::none: return "none";
    case FlowControl::rts_cts: return "rts/cts";
    case FlowControl::xon_xoff: return "xon/xoff";
  }
  return "?";
}

std::string settings_text(const SerialSettings& s) {
  const char parity = s.parity == Parity::none ? 'N' : s.parity == Parity::odd ? 'O' : 'E';
  std::string text = fmt::format("{} {}{}{}", s.baud, s.data_bits, parity, s.stop_bits);
  if (s.flow != FlowControl::none) text += fmt::format(" {}", flow_text(s.flow));
  return text;
}

}  // namespace lamina::drivers::detail
