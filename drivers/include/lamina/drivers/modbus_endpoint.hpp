#pragma once
// Where a PLC answers Modbus TCP and how patiently to talk to it — one struct for every
// owner of a Modbus connection (CellIo for the pump and interlocks, ModbusBlockLink for a
// controller fed through the mailbox), so a cell's PLC is described once.
#include <optional>
#include <string>
#include <string_view>
#include <utility>

namespace lamina::drivers {

struct ModbusEndpoint {
  std::string host = "127.0.0.1";
  int port = 502;
  int unit_id = 1;                 // the slave id in each request (a gateway routes by it)
  double response_timeout_s = 0.5;
  int max_reconnects = 3;          // per failed request, then the PLC is declared unreachable
  double backoff_s = 0.05;         // before reconnect k: k × this
};

// "HOST:PORT", an IPv6 host in brackets ("[::1]:502"); nullopt when malformed (no port, a port
// outside 1…65535, an IPv6 host without brackets, blanks or slashes in the host).
std::optional<std::pair<std::string, int>> parse_host_port(std::string_view text);

}  // namespace lamina::drivers
