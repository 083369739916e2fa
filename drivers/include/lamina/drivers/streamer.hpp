#pragma once
// A MachineLink over a byte stream: one Transport, one LineProtocol, one thread running a
// boost::asio::io_context. Real-time commands are written ahead of queued program bytes; the
// status is polled at a fixed period; every write's latency from request to wire is measured.
#include <expected>
#include <functional>
#include <memory>

#include "lamina/drivers/machine_link.hpp"
#include "lamina/drivers/transport.hpp"

namespace lamina::drivers {

struct StreamerSettings {
  double status_period_s = 0.2;    // 5 Hz '?' (0: no polling)
  double handshake_timeout_s = 5;  // banner / [OPT:] after connecting
  double silence_timeout_s = 10;   // lines in flight and nothing heard for this long: timeout
  // The controller reports Idle while a line waits for its answer: a lost `ok`, or a line that
  // never arrived whole — unless the line is one the controller answers only when done (a
  // dwell, a jet change, program end: line_wait.hpp). The stop comes after this margin (plus
  // the dwell's own time) and at least three such reports in a row.
  double stall_margin_s = 2;
  // Pace program bytes to the line rate (bytes/s, 0 = unpaced): what sits in a kernel buffer
  // cannot be held back by a DC3, so an XON/XOFF sender keeps that backlog small.
  double pace_bytes_per_s = 0;
};

// Opens the transport on the link's own io_context thread.
using TransportFactory =
    std::function<std::expected<std::unique_ptr<Transport>, LinkError>(boost::asio::io_context&)>;

struct RealtimeLatency {  // request() → bytes handed to the transport, seconds
  double max_s = 0;
  double mean_s = 0;
  std::size_t count = 0;
};

class Streamer final : public MachineLink {
 public:
  Streamer(TransportFactory open, std::unique_ptr<LineProtocol> protocol, StreamerSettings settings);
  ~Streamer() override;

  std::optional<LinkError> check_lines(const std::vector<std::string>& lines, std::size_t first_index) const override;
  void start(LineSpan span, LinkCallbacks callbacks) override;
  void request(RealtimeCommand command) override;
  void stop(LinkError why) override;
  LinkProgress progress() const override;
  std::optional<LinkError> recover(double timeout_s) override;
  bool can_reset() const override;
  std::optional<LinkError> reset(double timeout_s) override;
  std::optional<LinkOutcome> wait(double timeout_s) override;

  RealtimeLatency realtime_latency() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace lamina::drivers
