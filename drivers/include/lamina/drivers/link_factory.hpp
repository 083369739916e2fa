#pragma once
// The ways a program reaches the controller, registered once (issue 18), and the one place a
// link is built from its settings: `lamina stream` and laminad's machine session both call
// make_link. What differs between protocols — does the controller answer status queries (so
// the link polls it and a cut waits for it to stand Idle), does the program go over a serial or
// TCP line or through the PLC's Modbus mailbox — is a trait of the protocol's row, never a
// `protocol == "xonxoff"` at a call site.
#include <expected>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "lamina/drivers/cut_job.hpp"
#include "lamina/drivers/line_protocol.hpp"
#include "lamina/drivers/machine_link.hpp"
#include "lamina/drivers/modbus_endpoint.hpp"

namespace lamina::drivers {

// One struct for the link, whoever reads it (lamina.toml's [link], lamina stream's options).
struct LinkSettings {
  std::string protocol = "grbl";  // a name in link_protocols()
  std::string port;               // serial device or USB serial number
  std::string tcp;                // HOST:PORT of a networked controller
  int baud = 115200;
  std::size_t rx_buffer = 0;      // 0: as the controller reports (grbl)
  double status_hz = 5;
  double stall_margin_s = 2;      // Idle with lines unanswered this long (+ a dwell's P): a stall
  ModbusEndpoint plc;             // the PLC whose mailbox carries the blocks (a mailbox protocol)
};

struct LinkProtocolTraits {
  bool reports_status = true;  // answers '?': the link polls it, a cut waits for Idle at its end
  bool mailbox = false;        // blocks go through the PLC's Modbus mailbox, not a serial/TCP line
};

struct LinkProtocol {
  std::string_view name;     // as in lamina.toml and --protocol
  std::string_view summary;  // one line for help texts
  LinkProtocolTraits traits;
  std::unique_ptr<LineProtocol> (*make)(const LinkSettings&);  // null for the mailbox
};

std::span<const LinkProtocol> link_protocols();
const LinkProtocol* find_link_protocol(std::string_view name);
std::vector<std::string> link_protocol_names();
std::string link_protocol_names_text();  // "grbl, send-response, xonxoff, modbus"

struct BuiltLink {
  std::unique_ptr<MachineLink> link;
  const LinkProtocol* protocol = nullptr;
  std::string description;      // "grbl on /dev/ttyUSB0 at 115200 baud", "Modbus mailbox on 10.0.0.5:502"
  double line_bytes_per_s = 0;  // a serial line's rate (8N1), 0 otherwise
};

// Errors say which setting is wrong: an unknown protocol (listing the known ones), no port or
// TCP address for a line protocol (or both), a TCP address that is not HOST:PORT.
std::expected<BuiltLink, std::string> make_link(const LinkSettings& settings);

// The cut settings a protocol needs (a drip feed reports no status: nothing to wait for).
CutJobSettings cut_settings_for(const LinkProtocol& protocol);

}  // namespace lamina::drivers
