// Fanuc-style drip feed, remote buffer protocol B (see xonxoff_protocol.hpp).
//
// Decisions, since a Fanuc documents behaviour rather than an interface:
// - on_connect sends DC1: in protocol B the CNC asks for data with DC1 when its reader is
//   ready, so a sender that waits for DC1 before its first byte works (one that does not wait
//   loses nothing either: the buffer starts empty).
// - Bytes before the first `%` are ignored (tape leader), and so are bytes between a closing
//   `%` and the next opening one. NUL and DEL (tape feed / rub-out) are ignored everywhere.
// - A block the machine refuses (parse or modal error) raises GrblAlarm::program_error: a
//   Fanuc stops with an alarm instead of answering per line. Bytes over the margin after
//   DC3, or into a full buffer, raise GrblAlarm::buffer_overflow (Fanuc's PS087).
// - Any alarm → DC3 NAK, the buffer is flushed and input is lost until a reset.
// - external_reset (the operator's RESET) stops motion without an alarm, clears the alarm if
//   its cause is gone (unlock), sends DC3 SYN, flushes the buffer, and when the machine is out
//   of alarm sends DC1 and waits for a new `%`.
#include "xonxoff_protocol.hpp"

#include <algorithm>
#include <utility>

namespace lamina::sim {
namespace {

constexpr char kDc1 = 0x11;  // XON: send more
constexpr char kDc3 = 0x13;  // XOFF: stop sending
constexpr char kNak = 0x15;  // after DC3: stopped by an alarm
constexpr char kSyn = 0x16;  // after DC3: stopped by a reset

class XonXoffProtocol final : public CncProtocol {
 public:
  XonXoffProtocol(Machine& machine, XonXoffParams params) : machine_(machine), params_(params) {}

  void on_connect(double /*now_s*/) override {
    if (machine_.alarm()) return;  // nothing to ask for until a reset clears the alarm
    out_ += kDc1;
    xoff_ = xoff_on_wire_ = false;
  }

  void on_byte(std::uint8_t byte, double now_s) override {
    if (byte == 0x00 || byte == 0x7F) return;
    if (rx_state_ == RxState::halted) {
      ++counters_.bytes_dropped;  // the reader is stopped: what arrives is lost
      return;
    }
    if (rx_state_ == RxState::wait_start) {
      if (byte != '%') return;  // leader before the program
      rx_state_ = RxState::program;
    } else if (byte == '%') {
      rx_state_ = RxState::wait_start;  // the closing `%` (still stored: it ends the last line)
    }
    // The sender needs a few characters to react to DC3; beyond the margin it is overrunning.
    // Counted from when the DC3 went out, and not for bytes that were already waiting then
    // because the emulation slept (input_room() hands those over only as they fit).
    if (xoff_ && xoff_on_wire_) {
      if (transit_exempt_ > 0) {
        --transit_exempt_;
      } else if (++bytes_since_xoff_ > params_.overrun_margin_bytes) {
        overflow(now_s);
        return;
      }
    }
    if (buf_.size() >= params_.buffer_bytes) {
      overflow(now_s);
      return;
    }
    buf_.push_back(static_cast<char>(byte));
    ++counters_.bytes_received;
    if (!xoff_ && buf_.size() > params_.high_water_bytes) say_xoff();
  }

  void poll(double now_s) override {
    check_alarm();
    if (rx_state_ == RxState::halted) {
      if (machine_.alarm()) return;
      // Out of alarm (after a reset): ready for a new program.
      rx_state_ = RxState::wait_start;
      reset_line_state();
      out_ += kDc1;
      xoff_ = xoff_on_wire_ = false;
    }
    while (!stalled_ && take_line(now_s)) {
      if (check_alarm()) return;
    }
    if (xoff_ && buf_.size() < params_.low_water_bytes) {
        out_ += kDc1;
      xoff_ = xoff_on_wire_ = false;
      transit_exempt_ = 0;
    }
  }

  std::string take_output() override {
    taken_bytes_ += out_.size();
    return std::exchange(out_, {});
  }
  void on_output_sent(std::size_t bytes) override {
    sent_bytes_ += bytes;
    if (xoff_ && !xoff_on_wire_ && sent_bytes_ >= xoff_end_) {
      xoff_on_wire_ = true;
      bytes_since_xoff_ = 0;
      transit_exempt_ = rx_state_ == RxState::halted ? 0 : bytes_in_transit_;
    }
  }

  // Up to the byte that crosses the high-water mark; none while that DC3 waits to go out;
  // after it, the bytes that were in transit only as they fit with the margin still free for
  // what the sender writes before it sees the DC3 (those come after them); then anything (an
  // overrun is the sender's and raises the alarm).
  std::size_t input_room() const override {
    if (rx_state_ == RxState::halted) return std::numeric_limits<std::size_t>::max();
    if (!xoff_) return buf_.size() <= params_.high_water_bytes ? params_.high_water_bytes + 1 - buf_.size() : 1;
    if (!xoff_on_wire_) return 0;
    if (transit_exempt_ > 0) {
      const std::size_t free = rx_free(), margin = params_.overrun_margin_bytes;
      return std::min(transit_exempt_, free > margin ? free - margin : 0);
    }
    return std::numeric_limits<std::size_t>::max();
  }
  void set_bytes_in_transit(std::size_t bytes) override { bytes_in_transit_ = bytes; }
  void set_stalled(bool stalled) override { stalled_ = stalled; }

  void external_reset(double now_s) override {
    machine_.reset(now_s);  // a Fanuc RESET stops motion without an alarm of its own
    machine_.unlock();      // and clears the alarm when its cause is gone (not with e-stop)
    halt(kSyn);
    reported_alarm_ = machine_.alarm();
  }

  std::size_t rx_free() const override { return params_.buffer_bytes - buf_.size(); }
  const ProtocolCounters& counters() const override { return counters_; }

 private:
  enum class RxState { wait_start, program, halted };

  // Takes one block (EOB = LF, CR or CR LF; `%` ends the program). False when no complete
  // block is buffered, or it is a motion block and the planner is full: it stays in the
  // buffer (only motion fills the planner; other blocks pass once those before them have).
  bool take_line(double now_s) {
    const auto end = std::find_if(buf_.begin(), buf_.end(),
                                  [](char c) { return c == '\n' || c == '\r' || c == '%'; });
    if (end == buf_.end()) return false;
    const char term = *end;
    std::string line(buf_.begin(), end);
    if (!machine_.has_room_for(line)) return false;
    buf_.erase(buf_.begin(), std::next(end));

    if (term == '%') {
      // A program boundary. Text before a closing `%` on the same line is a last block.
      if (!line.empty()) submit(line, now_s);
      swallow_eob_ = true;  // the `%` line's own end of block is not a block
      last_eol_ = 0;
      return true;
    }
    if (line.empty()) {
      // CR LF is one EOB; and the EOB that ends a `%` line is not an empty block.
      const bool pair = last_eol_ != 0 && last_eol_ != term;
      if (pair || swallow_eob_) {
        last_eol_ = pair ? 0 : term;
        swallow_eob_ = false;
        return true;
      }
    }
    swallow_eob_ = false;
    last_eol_ = term;
    submit(line, now_s);
    return true;
  }

  void submit(const std::string& line, double now_s) {
    ++counters_.lines_received;
    const GrblStatus status = machine_.submit_line(line, now_s);
    // A soft-limit target raises its own alarm in the machine; other refusals raise ours.
    if (status != GrblStatus::ok && !machine_.alarm())
      machine_.raise_alarm(GrblAlarm::program_error, now_s);
  }

  // A new alarm stops the reader: DC3 NAK. True when the machine is in alarm.
  bool check_alarm() {
    const auto alarm = machine_.alarm();
    if (!alarm) {
      reported_alarm_.reset();
      return false;
    }
    if (reported_alarm_ != alarm) {
      reported_alarm_ = alarm;
      halt(kNak);
    }
    return true;
  }

  void overflow(double now_s) {
    ++counters_.bytes_dropped;
    machine_.raise_alarm(GrblAlarm::buffer_overflow, now_s);
    reported_alarm_ = machine_.alarm();
    halt(kNak);
  }

  // DC3 + reason; the buffer is flushed and input is lost until the machine is ready again.
  void halt(char reason) {
    say_xoff();
    out_ += reason;
    transit_exempt_ = 0;
    buf_.clear();
    rx_state_ = RxState::halted;
    reset_line_state();
  }

  // DC3 into the output; the sender can see it once the output up to it has crossed the wire.
  void say_xoff() {
    out_ += kDc3;
    xoff_end_ = taken_bytes_ + out_.size();
    xoff_ = true;
    xoff_on_wire_ = false;
    bytes_since_xoff_ = 0;
  }

  void reset_line_state() {
    last_eol_ = 0;
    swallow_eob_ = false;
  }

  Machine& machine_;
  XonXoffParams params_;
  std::string buf_;  // program bytes received and not yet taken as blocks
  std::string out_;
  ProtocolCounters counters_;
  RxState rx_state_ = RxState::wait_start;
  bool xoff_ = false;                  // DC3 sent, DC1 not yet
  bool xoff_on_wire_ = false;          // that DC3 has crossed the wire: the sender can see it
  std::uint64_t taken_bytes_ = 0;      // output handed to the link so far
  std::uint64_t sent_bytes_ = 0;       // of it, what crossed the wire
  std::uint64_t xoff_end_ = 0;         // output position just past the last DC3
  std::size_t bytes_since_xoff_ = 0;
  std::size_t bytes_in_transit_ = 0;  // waiting in the port because the emulation slept
  std::size_t transit_exempt_ = 0;    // of those, not yet taken since the DC3 went out
  bool stalled_ = false;
  char last_eol_ = 0;
  bool swallow_eob_ = false;
  std::optional<GrblAlarm> reported_alarm_;
};

}  // namespace

std::unique_ptr<CncProtocol> make_xonxoff_protocol(Machine& machine, XonXoffParams params) {
  return std::make_unique<XonXoffProtocol>(machine, params);
}

}  // namespace lamina::sim
