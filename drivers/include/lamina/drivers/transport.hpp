#pragma once
// One small interface per hardware boundary: a byte stream to the CNC. Implementations:
// libserialport for real serial ports (enumeration with USB ids, explicit settings), termios for
// device nodes libserialport 0.1.1 cannot open (PTYs — hence lamina-sim — and some RS-485
// cards), and TCP. All are driven by one boost::asio::io_context: completion handlers run on the
// thread that runs it. No vendor header leaks out of drivers/src.
#include <cstddef>
#include <cstdint>
#include <expected>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <system_error>
#include <vector>

#include "lamina/drivers/link_error.hpp"

namespace boost::asio {
class io_context;
}

namespace lamina::drivers {

enum class Parity { none, odd, even };
enum class FlowControl { none, rts_cts, xon_xoff };

// Every setting is applied explicitly: libserialport applies no defaults of its own.
struct SerialSettings {
  int baud = 115200;
  int data_bits = 8;
  Parity parity = Parity::none;
  int stop_bits = 1;
  FlowControl flow = FlowControl::none;
};

struct PortInfo {
  std::string name;           // /dev/ttyUSB0
  std::string description;
  std::string transport;      // usb, native, bluetooth
  std::optional<int> usb_vid, usb_pid;
  std::string usb_serial;     // stable across renumbering: open by it
  std::string manufacturer, product;
};

// Threads: open_* run on the caller's thread and need no running io_context (TCP connects on a
// private one and hands the socket over). After that, call async_read_some, async_write and
// close() from the thread that runs the io_context (post to it from elsewhere): Asio I/O objects
// are not thread-safe. Handlers run on that thread. At most one read and one write pending.
// Handler errors: std::errc::operation_canceled after close(); anything else means the link is
// gone or broken (EOF when the peer closes or a PTY is unplugged, EIO, ECONNRESET) — see
// to_link_error(). Destroy the transport before its io_context.
class Transport {
 public:
  using ReadHandler = std::function<void(std::error_code, std::size_t)>;
  using WriteHandler = std::function<void(std::error_code, std::size_t)>;
  virtual ~Transport() = default;
  // One read of whatever is there (at least one byte), like asio's async_read_some.
  virtual void async_read_some(std::span<std::uint8_t> buffer, ReadHandler handler) = 0;
  // Writes all of `data` (the buffer must stay alive until the handler runs).
  virtual void async_write(std::span<const std::uint8_t> data, WriteHandler handler) = 0;
  virtual void close() = 0;  // pending operations complete with operation_aborted; idempotent
  virtual std::string describe() const = 0;  // "serial /dev/ttyUSB0 115200 8N1", "tcp 127.0.0.1:23"
};

// What a failed read or write means for the link: cancelled after close(), io_error otherwise
// (the message names `where`, e.g. describe(), and the system's words).
LinkError to_link_error(std::error_code ec, const std::string& where);

// libserialport's view of the machine's ports.
std::expected<std::vector<PortInfo>, LinkError> list_serial_ports();

// `port` is a device path or a USB serial number (matched against list_serial_ports()).
// Real ports go through libserialport; a PTY (which libserialport 0.1.1 refuses) or a node it
// does not list goes through termios.
std::expected<std::unique_ptr<Transport>, LinkError> open_serial(boost::asio::io_context& io, const std::string& port,
                                                                 const SerialSettings& settings);
// termios directly (PTYs, RS-485 cards libserialport does not see).
std::expected<std::unique_ptr<Transport>, LinkError> open_termios(boost::asio::io_context& io, const std::string& path,
                                                                  const SerialSettings& settings);
// TCP with a connect timeout.
std::expected<std::unique_ptr<Transport>, LinkError> open_tcp(boost::asio::io_context& io, const std::string& host,
                                                              int port, double connect_timeout_s = 3.0);

}  // namespace lamina::drivers
