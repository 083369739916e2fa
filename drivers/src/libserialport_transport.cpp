// A real serial port: libserialport opens and configures it (every setting explicitly — the
// library applies no defaults, so a port keeps whatever the last program left otherwise), and
// Asio drives its file descriptor. libserialport owns that descriptor: Asio only borrows it and
// gives it back (release) before sp_close.
#include "libserialport_transport.hpp"

#include <boost/asio/io_context.hpp>
#include <boost/asio/posix/stream_descriptor.hpp>
#include <fmt/core.h>

#include "asio_stream_transport.hpp"
#include "libserialport_util.hpp"
#include "serial_settings.hpp"

namespace lamina::drivers::detail {

namespace {

using Descriptor = boost::asio::posix::stream_descriptor;

class LibserialportTransport final : public AsioStreamTransport<Descriptor> {
 public:
  LibserialportTransport(Descriptor descriptor, SpPortPtr port, std::string description)
      : AsioStreamTransport(std::move(descriptor), std::move(description)), port_(std::move(port)) {}
  // The base destructor would only see its own close_stream, which would close libserialport's fd.
  ~LibserialportTransport() override { close_stream(); }

 protected:
  void close_stream() override {
    if (!port_) return;  // idempotent
    // release() cancels pending operations (operation_aborted) and hands the fd back untouched.
    if (stream().is_open()) stream().release();
    sp_close(port_.get());
    port_.reset();
  }

 private:
  SpPortPtr port_;
};

struct PinSettings {
  sp_rts rts;
  sp_cts cts;
  sp_dtr dtr;
  sp_dsr dsr;
  sp_xonxoff xon_xoff;
};

// DTR stays on in every mode: it is what a terminal asserts, and boards that reset on DTR
// (Arduino-based Grbl) see one reset at open, as with every other sender.
PinSettings pins_for(FlowControl flow) {
  switch (flow) {
    case FlowControl::rts_cts:
      return {SP_RTS_FLOW_CONTROL, SP_CTS_FLOW_CONTROL, SP_DTR_ON, SP_DSR_IGNORE, SP_XONXOFF_DISABLED};
    case FlowControl::xon_xoff:
      return {SP_RTS_ON, SP_CTS_IGNORE, SP_DTR_ON, SP_DSR_IGNORE, SP_XONXOFF_INOUT};
    case FlowControl::none: break;
  }
  return {SP_RTS_ON, SP_CTS_IGNORE, SP_DTR_ON, SP_DSR_IGNORE, SP_XONXOFF_DISABLED};
}

sp_parity parity_for(Parity parity) {
  switch (parity) {
    case Parity::odd: return SP_PARITY_ODD;
    case Parity::even: return SP_PARITY_EVEN;
    case Parity::none: break;
  }
  return SP_PARITY_NONE;
}

LinkError configure_error(const std::string& device, const std::string& setting, sp_return result) {
  return LinkError{LinkErrorCode::configure_failed,
                   fmt::format("{}: {} refused: {}", device, setting, sp_error_text(result))};
}

// sp_set_config applies everything in one go, so its failure does not say which setting the
// driver refused: apply them one at a time to find it (the port is unusable either way).
LinkError name_refused_setting(sp_port* port, const std::string& device, const SerialSettings& s, sp_return whole) {
  const PinSettings pins = pins_for(s.flow);
  sp_return r;
  if ((r = sp_set_baudrate(port, s.baud)) != SP_OK) return configure_error(device, fmt::format("baud {}", s.baud), r);
  if ((r = sp_set_bits(port, s.data_bits)) != SP_OK)
    return configure_error(device, fmt::format("data bits {}", s.data_bits), r);
  if ((r = sp_set_parity(port, parity_for(s.parity))) != SP_OK) return configure_error(device, "parity", r);
  if ((r = sp_set_stopbits(port, s.stop_bits)) != SP_OK)
    return configure_error(device, fmt::format("stop bits {}", s.stop_bits), r);
  const std::string flow = fmt::format("flow control {}", flow_text(s.flow));
  if ((r = sp_set_rts(port, pins.rts)) != SP_OK) return configure_error(device, flow + " (RTS)", r);
  if ((r = sp_set_cts(port, pins.cts)) != SP_OK) return configure_error(device, flow + " (CTS)", r);
  if ((r = sp_set_dtr(port, pins.dtr)) != SP_OK) return configure_error(device, flow + " (DTR)", r);
  if ((r = sp_set_dsr(port, pins.dsr)) != SP_OK) return configure_error(device, flow + " (DSR)", r);
  if ((r = sp_set_xon_xoff(port, pins.xon_xoff)) != SP_OK) return configure_error(device, flow + " (XON/XOFF)", r);
  return configure_error(device, "configuration", whole);
}

std::expected<void, LinkError> configure(sp_port* port, const std::string& device, const SerialSettings& s) {
  sp_port_config* raw = nullptr;
  if (const sp_return r = sp_new_config(&raw); r != SP_OK) return std::unexpected(configure_error(device, "new config", r));
  SpConfigPtr config(raw);
  const PinSettings pins = pins_for(s.flow);
  // The sp_set_config_* calls only fill the structure; they fail on arguments alone.
  sp_return r = SP_OK;
  if ((r = sp_set_config_baudrate(raw, s.baud)) != SP_OK) return std::unexpected(configure_error(device, "baud", r));
  if ((r = sp_set_config_bits(raw, s.data_bits)) != SP_OK) return std::unexpected(configure_error(device, "data bits", r));
  if ((r = sp_set_config_parity(raw, parity_for(s.parity))) != SP_OK) return std::unexpected(configure_error(device, "parity", r));
  if ((r = sp_set_config_stopbits(raw, s.stop_bits)) != SP_OK) return std::unexpected(configure_error(device, "stop bits", r));
  if ((r = sp_set_config_rts(raw, pins.rts)) != SP_OK) return std::unexpected(configure_error(device, "RTS", r));
  if ((r = sp_set_config_cts(raw, pins.cts)) != SP_OK) return std::unexpected(configure_error(device, "CTS", r));
  if ((r = sp_set_config_dtr(raw, pins.dtr)) != SP_OK) return std::unexpected(configure_error(device, "DTR", r));
  if ((r = sp_set_config_dsr(raw, pins.dsr)) != SP_OK) return std::unexpected(configure_error(device, "DSR", r));
  if ((r = sp_set_config_xon_xoff(raw, pins.xon_xoff)) != SP_OK)
    return std::unexpected(configure_error(device, "XON/XOFF", r));
  if ((r = sp_set_config(port, raw)) != SP_OK) return std::unexpected(name_refused_setting(port, device, s, r));
  return {};
}

}  // namespace

std::expected<std::unique_ptr<Transport>, LinkError> open_libserialport(boost::asio::io_context& io,
                                                                        const std::string& device,
                                                                        const SerialSettings& settings,
                                                                        const std::string& label) {
  if (auto valid = validate(settings, device); !valid) return std::unexpected(valid.error());
  sp_port* raw = nullptr;
  if (const sp_return r = sp_get_port_by_name(device.c_str(), &raw); r != SP_OK)
    return std::unexpected(
        LinkError{LinkErrorCode::port_not_found, fmt::format("no serial port {}: {}", device, sp_error_text(r))});
  SpPortPtr port(raw);
  if (const sp_return r = sp_open(raw, SP_MODE_READ_WRITE); r != SP_OK)
    return std::unexpected(
        LinkError{LinkErrorCode::open_failed, fmt::format("cannot open {}: {}", device, sp_error_text(r))});
  auto close_port = [&] { sp_close(raw); };
  if (auto configured = configure(raw, device, settings); !configured) {
    close_port();
    return std::unexpected(configured.error());
  }
  (void)sp_flush(raw, SP_BUF_INPUT);  // replies meant for an earlier connection (as open_termios)
  int fd = -1;
  if (const sp_return r = sp_get_port_handle(raw, &fd); r != SP_OK || fd < 0) {
    close_port();
    return std::unexpected(
        LinkError{LinkErrorCode::open_failed, fmt::format("{}: no file descriptor: {}", device, sp_error_text(r))});
  }
  boost::system::error_code ec;
  Descriptor descriptor(io);
  descriptor.assign(fd, ec);
  if (ec) {
    close_port();
    return std::unexpected(
        LinkError{LinkErrorCode::open_failed, fmt::format("{}: cannot drive it with Asio: {}", device, ec.message())});
  }
  const std::string name = label.empty() ? device : fmt::format("{} {}", device, label);
  const std::string description = fmt::format("serial {} {}", name, settings_text(settings));
  return std::make_unique<LibserialportTransport>(std::move(descriptor), std::move(port), description);
}

}  // namespace lamina::drivers::detail
