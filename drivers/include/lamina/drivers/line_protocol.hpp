#pragma once
// A streaming protocol without I/O (sans-IO, like ruckig's data in / data out): it is told what
// arrived and asked what may be sent, so the same code runs over a serial port, a PTY or TCP,
// and its tests script the controller byte by byte. The Streamer (streamer.hpp) owns the I/O.
//
// Lines are the program's lines without end-of-line; `index` is the line's 0-based position in
// the program the caller loaded (so a resumed job keeps the original numbering).
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <limits>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "lamina/drivers/controller_status.hpp"
#include "lamina/drivers/link_error.hpp"

namespace lamina::drivers {

enum class RealtimeCommand { status, feed_hold, resume, reset };

struct LineSpan {  // lines [first, first + count) of the program, in order
  std::vector<std::string> lines;
  std::size_t first_index = 0;
};

// Events a protocol reports from received bytes.
struct LineAccepted {     // the controller took line `index` (Grbl `ok`; XON/XOFF: written out)
  std::size_t index = 0;
};
struct LineRejected {     // error:N on line `index`; the job must stop
  std::size_t index = 0;
  int code = 0;
  std::string meaning;    // "unsupported command (20)"
};
struct ControllerAlarm {  // ALARM:N, NAK after DC3: motion stopped, the job must stop
  int code = 0;
  std::string meaning;
};
struct ControllerReset {  // banner / SYN: the controller reset (queue flushed)
  std::string text;
};
struct StatusReceived {
  ControllerStatus status;
};
struct ControllerInfo {   // [OPT:…] / [AXS:…] / VER: what was learned at connect
  std::optional<int> planner_blocks;
  std::optional<int> rx_buffer_bytes;
  std::optional<int> axes;
  std::string axis_letters;
};
struct ProtocolViolation { // bytes that cannot be right (an ok with nothing in flight, garbage)
  std::string what;
};
using ProtocolEvent = std::variant<LineAccepted, LineRejected, ControllerAlarm, ControllerReset, StatusReceived,
                                   ControllerInfo, ProtocolViolation>;

class LineProtocol {
 public:
  virtual ~LineProtocol() = default;
  virtual std::string name() const = 0;

  // Bytes to send once after connecting, before any program line (e.g. "$I\n" to read the
  // buffer sizes); the protocol reports what it learned as ControllerInfo.
  virtual std::string handshake() = 0;
  virtual bool handshake_done() const = 0;

  // Before anything is sent: a line this protocol must not send — one that holds a byte the
  // controller takes as a real-time command wherever it stands, comments included (grbl: `?`
  // `!` `~` 0x18 and 0x80–0xFF; XON/XOFF: DC1–DC4 and a `%` inside the program). bad_request
  // naming the line (1-based), the column and what the byte would do.
  // `first_index` numbers the lines as in LineSpan. Const and stateless: callable from any thread.
  virtual std::optional<LinkError> check_lines(const std::vector<std::string>& lines, std::size_t first_index) const = 0;
  // Load lines to stream. Replaces whatever was loaded; nothing may be in flight.
  virtual void load(LineSpan span) = 0;
  // Bytes that may go on the wire now (window, XOFF, one-in-flight…), marked as sent, at most
  // `max_bytes` of them — but a whole line where the protocol sends whole lines, so a line
  // longer than the budget goes alone (the pacer's budget is then overrun by one line).
  virtual std::string take_sendable(std::size_t max_bytes) = 0;
  std::string take_sendable() { return take_sendable(std::numeric_limits<std::size_t>::max()); }
  // Stop handing out program bytes (after an error or alarm, or on the operator's stop).
  virtual void halt() = 0;
  // Bytes that arrived; the events they complete, in order.
  virtual std::vector<ProtocolEvent> on_received(std::string_view bytes) = 0;
  // Bytes for a real-time command, sent ahead of the line queue; empty when the protocol has
  // none (then the caller uses another path, e.g. the PLC).
  virtual std::string realtime(RealtimeCommand command) const = 0;
  // After an error:N, what to send to leave the controller's error lock the documented way
  // (grblHAL: an empty line) before anything else; empty if nothing is needed.
  virtual std::string clear_error_lock() const = 0;

  // Lines that take the controller out of an alarm after a reset (grbl: `$X`); streamed as a
  // span of their own by MachineLink::recover().
  virtual std::vector<std::string> unlock_lines() const { return {}; }

  // True while the controller has told us to stop sending (XON/XOFF's DC3).
  virtual bool flow_stopped() const { return false; }
  // The most program bytes the sender may have written ahead of the wire (0: no bound but
  // the pacing's). Under XON/XOFF that backlog is what still arrives after a DC3, so it must
  // fit the controller's tolerance (a Fanuc takes about 10 characters after DC3).
  virtual std::size_t max_backlog_bytes() const { return 0; }

  // What sits in the controller's receive buffer by our count: the bytes of every line sent and
  // not yet answered, and of the oldest of them (nullopt: the protocol does not count bytes).
  // Set against the controller's own free count, it tells a controller that stopped reading
  // from one whose answer was lost.
  struct Unanswered {
    std::size_t bytes = 0;
    std::size_t oldest_line_bytes = 0;
  };
  virtual std::optional<Unanswered> unanswered() const { return std::nullopt; }

  virtual std::size_t lines_sent() const = 0;      // of the loaded span
  virtual std::size_t lines_accepted() const = 0;  // acknowledged (or, for XON/XOFF, written)
  virtual bool finished() const = 0;               // every loaded line accepted
};

struct GrblProtocolSettings {
  // 0: learn the receive buffer from `[OPT:…]` at the handshake (grblHAL reports it); a Grbl
  // that does not report it gets 128 (classic Grbl), unless configured.
  std::size_t rx_buffer_bytes = 0;
};
struct XonXoffProtocolSettings {
  std::size_t chunk_bytes = 16;  // most bytes handed out per call: a DC3 stops us within this
  bool send_percent_frame = true;  // `%` before and after the program when the program lacks it
};

// Grbl character counting. handshake() sends `$I`; its `ok` ends the handshake with a
// ControllerInfo whose rx_buffer_bytes is the receive buffer in use (configured, else
// `[OPT:]`, else 128); unanswered lines are kept within one byte less, what a ring buffer of
// that size holds. A banner (ControllerReset) during the handshake loses the `$I`: call handshake() again.
// After LineRejected the caller sends clear_error_lock() (the protocol expects its `ok`); the
// lines already in flight are answered by the error lock (or, after ALARM, refused or
// flushed) and reported as nothing. A banner halts and forgets the lines in flight.
std::unique_ptr<LineProtocol> make_grbl_protocol(GrblProtocolSettings settings = {});
// The same grammar with one line in flight and no handshake.
std::unique_ptr<LineProtocol> make_send_response_protocol();  // one line in flight, ok/error
// XON/XOFF: lines_accepted() counts a line once its LF is handed out; its LineAccepted event
// comes with the next on_received() (take_sendable cannot report events). finished() waits
// for the closing `%` too. No real-time bytes: hold, resume and reset go through the PLC.
std::unique_ptr<LineProtocol> make_xonxoff_protocol(XonXoffProtocolSettings settings = {});

}  // namespace lamina::drivers
