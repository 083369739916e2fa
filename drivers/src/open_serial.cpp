// open_serial(): one name for a port, whichever way the cell file gives it — a device path, or a
// USB serial number (stable when /dev/ttyUSB* renumbers) — and the right driver for it.
#include <filesystem>

#include <fmt/core.h>

#include "libserialport_transport.hpp"
#include "lamina/drivers/transport.hpp"

namespace lamina::drivers {

namespace {

std::string canonical_or_self(const std::string& path) {
  std::error_code ec;
  const auto real = std::filesystem::canonical(path, ec);
  return ec ? path : real.string();
}

std::string port_names(const std::vector<PortInfo>& ports) {
  if (ports.empty()) return "none";
  std::string text;
  for (const auto& p : ports) {
    if (!text.empty()) text += ", ";
    text += p.name;
    if (!p.usb_serial.empty()) text += fmt::format(" (usb serial {})", p.usb_serial);
  }
  return text;
}

// A path is anything with a slash; a bare word is a USB serial number.
bool looks_like_path(const std::string& port) { return port.find('/') != std::string::npos; }

}  // namespace

std::expected<std::unique_ptr<Transport>, LinkError> open_serial(boost::asio::io_context& io, const std::string& port,
                                                                 const SerialSettings& settings) {
  // An enumeration failure is not fatal for a path: termios can still open the node.
  const auto listed = list_serial_ports();
  const std::vector<PortInfo> ports = listed ? *listed : std::vector<PortInfo>{};

  std::error_code ec;
  if (looks_like_path(port) || std::filesystem::exists(port, ec)) {
    if (!std::filesystem::exists(port, ec))
      return std::unexpected(LinkError{LinkErrorCode::port_not_found, fmt::format("no such device {}", port)});
    const std::string real = canonical_or_self(port);
    // libserialport 0.1.1 refuses PTYs and cannot see some RS-485 cards: termios for those.
    if (real.starts_with("/dev/pts/")) return open_termios(io, port, settings);
    for (const auto& p : ports)
      if (canonical_or_self(p.name) == real) return detail::open_libserialport(io, p.name, settings, {});
    return open_termios(io, port, settings);
  }

  for (const auto& p : ports)
    if (!p.usb_serial.empty() && p.usb_serial == port)
      return detail::open_libserialport(io, p.name, settings, fmt::format("(usb serial {})", port));
  const std::string why = listed ? port_names(ports) : fmt::format("unknown: {}", listed.error().message);
  return std::unexpected(LinkError{LinkErrorCode::port_not_found,
                                   fmt::format("no serial port with USB serial number {}; ports: {}", port, why)});
}

}  // namespace lamina::drivers
