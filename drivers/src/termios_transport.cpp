// open_termios(): device nodes libserialport will not open — PTYs (lamina-sim) and some RS-485
// cards — through boost::asio::serial_port, which opens non-blocking without a controlling tty
// and puts the line in raw mode (cfmakeraw) before our settings are applied.
#include <termios.h>

#include <array>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <limits>

#include <boost/asio/io_context.hpp>
#include <boost/asio/serial_port.hpp>
#include <fmt/core.h>

#include "asio_stream_transport.hpp"
#include "serial_settings.hpp"

namespace lamina::drivers {

namespace {

using SerialPort = boost::asio::serial_port;

// The rates asio's baud_rate option maps to a Bxxx constant on Linux. A rate within a UART's
// tolerance of one of them (2%: both ends may be off by a little under that) is rounded to it;
// anything else is refused rather than silently run at a wrong speed.
constexpr std::array<int, 27> kStandardBauds = {50,     75,     110,    134,    150,     200,     300,
                                                600,    1200,   1800,   2400,   4800,    9600,    19200,
                                                38400,  57600,  115200, 230400, 460800,  500000,  576000,
                                                921600, 1000000, 1152000, 2000000, 3000000, 4000000};
constexpr double kBaudTolerance = 0.02;

std::expected<int, LinkError> nearest_standard_baud(int baud, const std::string& path) {
  int best = kStandardBauds.front();
  for (int b : kStandardBauds)
    if (std::abs(b - baud) < std::abs(best - baud)) best = b;
  if (std::abs(best - baud) > kBaudTolerance * best)
    return std::unexpected(LinkError{LinkErrorCode::configure_failed,
                                     fmt::format("{}: baud {} refused: termios has no such rate (nearest {})", path,
                                                 baud, best)});
  return best;
}

bool is_pty(const std::string& path) {
  std::error_code ec;
  const auto real = std::filesystem::canonical(path, ec);
  return !ec && real.string().starts_with("/dev/pts/");
}

LinkError option_error(const std::string& path, const std::string& setting, const boost::system::error_code& ec) {
  return LinkError{LinkErrorCode::configure_failed, fmt::format("{}: {} refused: {}", path, setting, ec.message())};
}

std::expected<void, LinkError> apply(SerialPort& port, const std::string& path, const SerialSettings& s, int baud) {
  using Base = boost::asio::serial_port_base;
  boost::system::error_code ec;
  port.set_option(Base::baud_rate(static_cast<unsigned>(baud)), ec);
  if (ec) return std::unexpected(option_error(path, fmt::format("baud {}", baud), ec));
  port.set_option(Base::character_size(static_cast<unsigned>(s.data_bits)), ec);
  if (ec) return std::unexpected(option_error(path, fmt::format("data bits {}", s.data_bits), ec));
  const auto parity = s.parity == Parity::odd    ? Base::parity::odd
                      : s.parity == Parity::even ? Base::parity::even
                                                 : Base::parity::none;
  port.set_option(Base::parity(parity), ec);
  if (ec) return std::unexpected(option_error(path, "parity", ec));
  port.set_option(Base::stop_bits(s.stop_bits == 2 ? Base::stop_bits::two : Base::stop_bits::one), ec);
  if (ec) return std::unexpected(option_error(path, fmt::format("stop bits {}", s.stop_bits), ec));
  const auto flow = s.flow == FlowControl::rts_cts    ? Base::flow_control::hardware
                    : s.flow == FlowControl::xon_xoff ? Base::flow_control::software
                                                      : Base::flow_control::none;
  port.set_option(Base::flow_control(flow), ec);
  if (ec) return std::unexpected(option_error(path, fmt::format("flow control {}", detail::flow_text(s.flow)), ec));
  return {};
}

// asio's open() relies on cfmakeraw; check the result, because a line that echoes or cooks
// would send the controller's own output back to it (on a PTY the echo goes to the peer).
std::expected<void, LinkError> check_raw(SerialPort& port, const std::string& path) {
  termios t{};
  if (::tcgetattr(port.native_handle(), &t) != 0)
    return std::unexpected(LinkError{LinkErrorCode::configure_failed, fmt::format("{}: cannot read termios", path)});
  if ((t.c_lflag & (ICANON | ECHO | ECHONL | ISIG | IEXTEN)) || (t.c_oflag & OPOST) ||
      (t.c_iflag & (ICRNL | INLCR | IGNCR | ISTRIP)))
    return std::unexpected(LinkError{LinkErrorCode::configure_failed,
                                     fmt::format("{}: the line is not raw after configuration (echo or line editing)", path)});
  return {};
}

}  // namespace

std::expected<std::unique_ptr<Transport>, LinkError> open_termios(boost::asio::io_context& io, const std::string& path,
                                                                  const SerialSettings& settings) {
  if (auto valid = detail::validate(settings, path); !valid) return std::unexpected(valid.error());
  std::error_code exists_ec;
  if (!std::filesystem::exists(path, exists_ec))
    return std::unexpected(LinkError{LinkErrorCode::port_not_found, fmt::format("no such device {}", path)});
  auto baud = nearest_standard_baud(settings.baud, path);
  if (!baud) return std::unexpected(baud.error());

  SerialPort port(io);
  boost::system::error_code ec;
  port.open(path, ec);
  if (ec) {
    // It vanished between the check and the open (an unplug) or it is not ours to open.
    const LinkErrorCode code = ec == boost::system::errc::no_such_file_or_directory ? LinkErrorCode::port_not_found
                                                                                   : LinkErrorCode::open_failed;
    return std::unexpected(LinkError{code, fmt::format("cannot open {}: {}", path, ec.message())});
  }
  if (auto applied = apply(port, path, settings, *baud); !applied) return std::unexpected(applied.error());
  if (auto raw = check_raw(port, path); !raw) return std::unexpected(raw.error());
  // What the controller said to an earlier connection (acks of a host that died) is not an
  // answer to us: drop what is buffered; the Streamer ignores stragglers until the banner.
  ::tcflush(port.native_handle(), TCIFLUSH);

  SerialSettings actual = settings;
  actual.baud = *baud;  // describe what the line runs at
  const std::string description =
      fmt::format("{} {} (termios) {}", is_pty(path) ? "pty" : "serial", path, detail::settings_text(actual));
  return std::make_unique<detail::AsioStreamTransport<SerialPort>>(std::move(port), description);
}

}  // namespace lamina::drivers
