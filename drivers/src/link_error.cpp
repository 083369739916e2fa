#include "lamina/drivers/link_error.hpp"

namespace lamina::drivers {

const char* to_string(LinkErrorCode code) {
  switch (code) {
    case LinkErrorCode::port_not_found: return "port_not_found";
    case LinkErrorCode::open_failed: return "open_failed";
    case LinkErrorCode::configure_failed: return "configure_failed";
    case LinkErrorCode::io_error: return "io_error";
    case LinkErrorCode::timeout: return "timeout";
    case LinkErrorCode::protocol_error: return "protocol_error";
    case LinkErrorCode::controller_error: return "controller_error";
    case LinkErrorCode::controller_alarm: return "controller_alarm";
    case LinkErrorCode::interlock: return "interlock";
    case LinkErrorCode::modbus_error: return "modbus_error";
    case LinkErrorCode::cancelled: return "cancelled";
    case LinkErrorCode::bad_request: return "bad_request";
    case LinkErrorCode::controller_held: return "controller_held";
    case LinkErrorCode::held_too_long: return "held_too_long";
    case LinkErrorCode::left_hold_without_jet: return "left_hold_without_jet";
    case LinkErrorCode::starved: return "starved";
  }
  return "unknown";
}

}  // namespace lamina::drivers
