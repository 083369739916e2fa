#include "lamina/drivers/link_factory.hpp"

#include <fmt/format.h>

#include "lamina/drivers/modbus_block_link.hpp"
#include "lamina/drivers/streamer.hpp"
#include "lamina/drivers/transport.hpp"

namespace lamina::drivers {
namespace {

std::unique_ptr<LineProtocol> make_grbl(const LinkSettings& s) { return make_grbl_protocol({s.rx_buffer}); }
std::unique_ptr<LineProtocol> make_send_response(const LinkSettings&) { return make_send_response_protocol(); }
std::unique_ptr<LineProtocol> make_xonxoff(const LinkSettings&) { return make_xonxoff_protocol(); }

constexpr LinkProtocol kProtocols[] = {
    {"grbl", "grbl/grblHAL character counting: the receive buffer kept full, status polled", {true, false}, make_grbl},
    {"send-response", "one line in flight, each answered ok or error", {true, false}, make_send_response},
    {"xonxoff", "a drip feed paced by the controller's XON/XOFF; no status", {false, false}, make_xonxoff},
    {"modbus", "blocks through the cell PLC's Modbus mailbox", {true, true}, nullptr},
};

std::string host_port_text(const ModbusEndpoint& e) {
  return e.host.find(':') != std::string::npos ? fmt::format("[{}]:{}", e.host, e.port)
                                               : fmt::format("{}:{}", e.host, e.port);
}

BuiltLink mailbox_link(const LinkSettings& s, const LinkProtocol& protocol) {
  ModbusBlockSettings m;
  m.plc = s.plc;
  m.status_period_s = 1.0 / s.status_hz;
  return {std::make_unique<ModbusBlockLink>(m), &protocol, fmt::format("Modbus mailbox on {}", host_port_text(s.plc)), 0};
}

}  // namespace

std::span<const LinkProtocol> link_protocols() { return kProtocols; }

const LinkProtocol* find_link_protocol(std::string_view name) {
  for (const LinkProtocol& p : kProtocols)
    if (p.name == name) return &p;
  return nullptr;
}

std::vector<std::string> link_protocol_names() {
  std::vector<std::string> names;
  for (const LinkProtocol& p : kProtocols) names.emplace_back(p.name);
  return names;
}

std::string link_protocol_names_text() {
  std::string text;
  for (const LinkProtocol& p : kProtocols) text += (text.empty() ? "" : ", ") + std::string(p.name);
  return text;
}

std::expected<BuiltLink, std::string> make_link(const LinkSettings& s) {
  const LinkProtocol* protocol = find_link_protocol(s.protocol);
  if (!protocol)
    return std::unexpected(fmt::format("protocol '{}' is unknown (known: {})", s.protocol, link_protocol_names_text()));
  if (protocol->traits.mailbox) return mailbox_link(s, *protocol);
  if (s.port.empty() == s.tcp.empty()) return std::unexpected("give a serial port or a TCP address (one of them)");

  StreamerSettings settings;
  settings.status_period_s = protocol->traits.reports_status ? 1.0 / s.status_hz : 0;
  settings.stall_margin_s = s.stall_margin_s;
  BuiltLink built;
  built.protocol = protocol;
  TransportFactory open;
  if (!s.port.empty()) {
    SerialSettings serial;
    serial.baud = s.baud;
    built.line_bytes_per_s = s.baud / 10.0;  // 8N1
    settings.pace_bytes_per_s = built.line_bytes_per_s;
    open = [port = s.port, serial](boost::asio::io_context& io) { return open_serial(io, port, serial); };
    built.description = fmt::format("{} on {} at {} baud", protocol->name, s.port, s.baud);
  } else {
    auto hp = parse_host_port(s.tcp);
    if (!hp) return std::unexpected(fmt::format("tcp '{}': expected HOST:PORT (\"[::1]:PORT\" for IPv6)", s.tcp));
    open = [host = hp->first, port = hp->second](boost::asio::io_context& io) { return open_tcp(io, host, port); };
    built.description = fmt::format("{} on tcp {}", protocol->name, s.tcp);
  }
  built.link = std::make_unique<Streamer>(std::move(open), protocol->make(s), settings);
  return built;
}

CutJobSettings cut_settings_for(const LinkProtocol& protocol) {
  CutJobSettings c;
  c.wait_for_idle = protocol.traits.reports_status;  // a drip feed reports no status
  return c;
}

}  // namespace lamina::drivers
