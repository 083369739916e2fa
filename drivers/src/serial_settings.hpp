#pragma once
// Internal: what every serial transport does with SerialSettings before touching a driver —
// reject values no UART has, and spell the settings the way operators read them ("115200 8N1").
#include <expected>
#include <string>

#include "lamina/drivers/link_error.hpp"
#include "lamina/drivers/transport.hpp"

namespace lamina::drivers::detail {

// bad_request naming the setting when a value is outside what any serial port takes (data bits
// 5–8, stop bits 1–2, a positive baud); whether the driver accepts it is the transport's check.
std::expected<void, LinkError> validate(const SerialSettings& settings, const std::string& port);

// "115200 8N1", then " rts/cts" or " xon/xoff" when there is flow control.
std::string settings_text(const SerialSettings& settings);

const char* flow_text(FlowControl flow);

}  // namespace lamina::drivers::detail
