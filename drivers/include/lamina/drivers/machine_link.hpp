#pragma once
// What a job needs from the link to the CNC, whatever carries it: a byte stream with a
// LineProtocol (streamer.hpp) or the PLC's G-code block mailbox (modbus_block_link.hpp).
// Thread-safe: request() and stop() may be called from any thread; events are delivered on the
// link's own thread.
#include <cstddef>
#include <functional>
#include <optional>
#include <string>

#include "lamina/drivers/controller_status.hpp"
#include "lamina/drivers/line_protocol.hpp"
#include "lamina/drivers/link_error.hpp"

namespace lamina::drivers {

struct LinkProgress {
  std::size_t lines_total = 0;     // in the loaded span
  std::size_t lines_sent = 0;
  std::size_t lines_accepted = 0;  // acknowledged by the controller
  std::size_t bytes_sent = 0;
  double seconds = 0;              // since start()
  std::optional<ControllerStatus> last_status;
  std::size_t statuses_received = 0;     // counts reports, so a caller can wait for a fresh one
  std::optional<int> planner_blocks;     // as the controller reported at the handshake
  std::optional<int> rx_buffer_bytes;
};

// The link's view of how streaming ended (or why it stopped).
struct LinkOutcome {
  bool completed = false;          // every line accepted
  std::optional<LinkError> error;  // set when it stopped early
  std::size_t lines_accepted = 0;       // of the span started
  std::size_t last_accepted_index = 0;  // program index of the last accepted line (first_index if none)
};

struct LinkCallbacks {
  std::function<void(const LinkProgress&)> on_progress;     // at most every status period
  std::function<void(const ControllerStatus&)> on_status;
  std::function<void(const LinkOutcome&)> on_done;          // once per start()
};

class MachineLink {
 public:
  virtual ~MachineLink() = default;
  // Before anything is sent: a line this link must not carry (a real-time byte of its
  // protocol, a block too long for the mailbox), as bad_request naming it. start() checks too.
  virtual std::optional<LinkError> check_lines(const std::vector<std::string>& lines, std::size_t first_index) const = 0;
  // Connect (if needed), run the protocol's handshake and stream `span`. Returns at once.
  virtual void start(LineSpan span, LinkCallbacks callbacks) = 0;
  // Real-time command, ahead of the queue (feed hold, resume, reset, status).
  virtual void request(RealtimeCommand command) = 0;
  // Stop streaming (no more lines); does not move the machine. on_done follows.
  virtual void stop(LinkError why) = 0;
  virtual LinkProgress progress() const = 0;
  // After a stop, before streaming from a resume point: clear the controller's queue and its
  // alarm or error lock (grbl: soft reset, then $X). Blocking.
  virtual std::optional<LinkError> recover(double timeout_s) = 0;
  // Whether recover() can reset the controller at all (a drip feed's line cannot: the PLC can).
  virtual bool can_reset() const = 0;
  // The soft reset alone (grbl: 0x18), waiting for the controller to say it reset; no unlock,
  // so an alarm stays for the operator to see. Motion, queue and the jet's M-code are gone.
  // What a stop does where no PLC can turn the jet off. Blocking.
  virtual std::optional<LinkError> reset(double timeout_s) {
    (void)timeout_s;
    return LinkError{LinkErrorCode::bad_request, "this link has no reset of its own"};
  }
  // Blocks until the last start() finished; nullopt on timeout.
  virtual std::optional<LinkOutcome> wait(double timeout_s) = 0;
};

}  // namespace lamina::drivers
