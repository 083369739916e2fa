#pragma once
// Errors of the machine link, with stable codes (append only: scripts and the daemon's API
// match on the numbers). The message names what failed and where (port, line, register).
#include <string>

namespace lamina::drivers {

enum class LinkErrorCode : int {
  port_not_found = 1,     // no such device, or no port with that USB serial number
  open_failed = 2,        // the port exists but cannot be opened (busy, permission)
  configure_failed = 3,   // baud / parity / flow control refused by the driver
  io_error = 4,           // read/write failed: unplugged cable, EIO, connection reset
  timeout = 5,            // no answer within the protocol's time
  protocol_error = 6,     // bytes that make no sense for the protocol (garbled, unexpected ack)
  controller_error = 7,   // the controller refused a line (error:N)
  controller_alarm = 8,   // ALARM:N, NAK, or the controller reset itself (SYN / banner)
  interlock = 9,          // e-stop, door, pressure, heartbeat: the cell is not safe to cut
  modbus_error = 10,      // Modbus transport or exception response
  cancelled = 11,         // the operator or the caller stopped it
  bad_request = 12,       // a malformed argument (address, settings)
  controller_held = 13,   // in feed hold or with its door open before our first line: it would run nothing
  held_too_long = 14,     // a feed hold outlasted [cut] hold_limit_s: it became a stop
  left_hold_without_jet = 15,  // the machine left a hold by itself while the hold had the jet off
  starved = 16,           // a hold's reason: the controller ran out of program with the jet on
};

struct LinkError {
  LinkErrorCode code{};
  std::string message;
};

const char* to_string(LinkErrorCode code);

}  // namespace lamina::drivers
