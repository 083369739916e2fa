// grblHAL-like line protocol (see grbl_protocol.hpp). Behaviour follows grblHAL/core
// protocol.c (line assembly, real-time byte filter, the error lock) and report.c (formats,
// in grbl_reports.cpp). Deliberate simplifications are marked "Simplification:".
#include "grbl_protocol.hpp"

#include <algorithm>
#include <cctype>
#include <deque>
#include <utility>

#include <fmt/format.h>

#include "grbl_reports.hpp"

namespace lamina::sim {
namespace {

// grblHAL's Status_EStop: `$X` refused while the e-stop input is still active. Not in
// GrblStatus because only the protocol answers it.
constexpr int kStatusEStop = 50;

constexpr std::uint8_t kReset = 0x18;            // ctrl-X
constexpr std::uint8_t kStatusReport = 0x80;     // grblHAL's extended aliases of ? ~ !
constexpr std::uint8_t kCycleStart = 0x81;
constexpr std::uint8_t kFeedHold = 0x82;
constexpr std::uint8_t kStatusReportAll = 0x87;

class GrblProtocol final : public CncProtocol {
 public:
  GrblProtocol(Machine& machine, GrblParams params)
      : machine_(machine), params_(params), planner_blocks_(machine.planner_blocks()) {}

  // report_init_message: the banner, at power-up and after every reset (whether a host opening
  // the port brings one is the runtime's --on-open); it restarts the status report counters.
  void on_connect(double /*now_s*/) override {
    out_ += grbl::banner();
    reporter_.restart();
    if (machine_.alarm()) out_ += fmt::format("[MSG:'$H'|'$X' to unlock]{}", grbl::kEol);
  }

  void on_byte(std::uint8_t byte, double now_s) override {
    // Real-time bytes are picked off the stream on arrival (grblHAL does it in the UART
    // interrupt), so they work even when the receive buffer is full and never take a place
    // in it. grblHAL keeps legacy ? ! ~ real-time by default ($-setting RT+).
    switch (byte) {
      case kReset: soft_reset(now_s); return;
      case '?':
      case kStatusReport:
      case kStatusReportAll:
        machine_.advance(now_s);  // report the state as of this instant
        out_ += reporter_.report(machine_, rx_free(), now_s);
        return;
      case '!':
      case kFeedHold: machine_.feed_hold(now_s); return;
      case '~':
      case kCycleStart: machine_.cycle_start(now_s); return;
      case '\n':
      case '\r':
        // A line behind a running dwell: the controller takes it the moment the dwell ends.
        if (awaiting_dwell_) machine_.expect_line_after_dwell();
        break;
      default:
        // grblHAL drops other control characters, DEL and every top-bit byte it has no
        // handler for (0x84 safety door included: the simulator has no door state).
        if (byte < 0x20 || byte >= 0x7F) return;
    }
    if (rx_.size() >= rx_capacity()) {
      ++counters_.bytes_dropped;  // a full UART ring: the byte is lost, as on hardware
      return;
    }
    rx_.push_back(static_cast<char>(byte));
    ++counters_.bytes_received;
  }

  void poll(double now_s) override {
    report_alarm_change();
    finish_dwell();
    while (!stalled_ && !awaiting_dwell_) {
      if (!take_line(now_s)) break;
      report_alarm_change();
      finish_dwell();
    }
  }

  std::string take_output() override { return std::exchange(out_, {}); }
  void set_stalled(bool stalled) override { stalled_ = stalled; }
  void external_reset(double now_s) override { soft_reset(now_s); }
  std::size_t rx_free() const override { return rx_capacity() - rx_.size(); }
  const ProtocolCounters& counters() const override { return counters_; }

 private:
  // Takes and answers one complete line. False when there is none, or it is a motion line and
  // the planner is full (the line waits in the receive buffer: that back-pressure is what a
  // character-counting sender sees in the missing `ok`). Comments and modal-only lines take no
  // planner block, so they pass as soon as every line before them has: a host may then count
  // executed lines as acknowledged lines minus the motion blocks that Bf says are queued.
  bool take_line(double now_s) {
    const auto eol_it = std::find_if(rx_.begin(), rx_.end(), [](char c) { return c == '\n' || c == '\r'; });
    if (eol_it == rx_.end()) return false;
    const char eol = *eol_it;
    const auto raw_len = static_cast<std::size_t>(eol_it - rx_.begin());

    // CR LF (or LF CR) is one end of line: the second one ends an empty line, which grblHAL
    // swallows instead of answering a second `ok`.
    if (raw_len == 0 && last_eol_ != 0 && last_eol_ != eol) {
      rx_.pop_front();
      last_eol_ = 0;
      return true;
    }

    // grblHAL strips leading whitespace and control characters while assembling the line.
    std::string line;
    bool overflow = false;
    for (auto it = rx_.begin(); it != eol_it; ++it) {
      const char c = *it;
      if (line.empty() && c == ' ') continue;
      if (line.size() >= kLineBufferChars) {
        overflow = true;
        continue;
      }
      line += c;
    }

    const bool is_gcode = !overflow && !line.empty() && line.front() != '$';
    const bool locked = is_gcode && (machine_.state() == MachineState::alarm || last_error_ != 0);
    if (is_gcode && !locked && !machine_.has_room_for(line)) return false;

    rx_.erase(rx_.begin(), std::next(eol_it));
    last_eol_ = eol;
    ++counters_.lines_received;

    if (overflow) {
      answer(static_cast<int>(GrblStatus::overflow));
    } else if (line.empty()) {
      answer(0);  // the sync line: also clears the error lock
    } else if (line.front() == '$') {
      answer(system_command(line));
    } else if (machine_.state() == MachineState::alarm) {
      answer(static_cast<int>(GrblStatus::system_gc_lock));
    } else if (last_error_ != 0) {
      // The error lock (grblHAL, compatibility level 0): after an error the following G-code
      // lines are not executed and answered with the same error again, so a streaming
      // sender cannot run the rest of a program whose earlier line failed.
      answer(last_error_);
    } else {
      execute_gcode(line, now_s);
    }
    return true;
  }

  // grblHAL's serial ring buffer (RX_BUFFER_SIZE bytes) tells a full ring from an empty one by
  // keeping one slot free: it holds size − 1 bytes, and serialRxFree reports
  // (RX_BUFFER_SIZE − 1) − count. $I's [OPT:] still names the size.
  std::size_t rx_capacity() const { return params_.rx_buffer_bytes > 0 ? params_.rx_buffer_bytes - 1 : 0; }

  // The dwell's `ok` comes when mc_dwell returns, after the dwell. A reset or an alarm (grblHAL
  // aborts: sys.abort ends delay_sec) drops the line unanswered.
  void finish_dwell() {
    if (!awaiting_dwell_ || machine_.pending(*awaiting_dwell_)) {
      if (awaiting_dwell_ && has_complete_line()) machine_.expect_line_after_dwell();
      return;
    }
    awaiting_dwell_.reset();
    if (!machine_.alarm()) answer(0);
  }
  bool has_complete_line() const {
    return std::any_of(rx_.begin(), rx_.end(), [](char c) { return c == '\n' || c == '\r'; });
  }

  // Runs an accepted G-code line and answers it — at once, or (a dwell) when it is done.
  void execute_gcode(const std::string& line, double now_s) {
    const GrblStatus status = machine_.submit_line(line, now_s);
    report_alarm_change();  // a soft-limit target: ALARM:2 first, then the line's error:10
    if (status != GrblStatus::ok) {
      answer(static_cast<int>(status));
      return;
    }
    const ParseResult parsed = parse_block(line, ParseParams{});
    track_modal(parsed);
    if (parsed.block.motion == MotionMode::dwell && machine_.pending(machine_.accepted_blocks())) {
      awaiting_dwell_ = machine_.accepted_blocks();
      return;
    }
    // gc_execute_block's program end reports Message_ProgramEnd before the line's ok.
    if (parsed.block.program_end) out_ += fmt::format("[MSG:Pgm End]{}", grbl::kEol);
    answer(0);
  }

  // `ok`, or `error:N`; every answer also sets grblHAL's gc_state.last_error.
  void answer(int status) {
    last_error_ = status;
    if (status != 0) {
      out_ += fmt::format("error:{}{}", status, grbl::kEol);
      ++counters_.errors_sent;
      return;
    }
    ++ok_index_;
    if (params_.faults.drop_ok_index && *params_.faults.drop_ok_index == ok_index_) {
      ++counters_.oks_dropped;  // fault: this `ok` is lost on the wire
      return;
    }
    out_ += fmt::format("ok{}", grbl::kEol);
    ++counters_.oks_sent;
  }

  int system_command(const std::string& line) {
    std::string cmd = line;
    std::transform(cmd.begin(), cmd.end(), cmd.begin(), [](unsigned char c) { return std::toupper(c); });
    std::erase(cmd, ' ');
    if (cmd == "$") {
      out_ += grbl::help();
    } else if (cmd == "$I") {
      out_ += grbl::build_info(planner_blocks_, params_.rx_buffer_bytes);
    } else if (cmd == "$G") {
      out_ += grbl::parser_state(modal_, machine_.accessories());
    } else if (cmd == "$$") {
      out_ += grbl::settings_dump();
    } else if (cmd == "$X") {
      if (machine_.state() == MachineState::alarm) {
        if (!machine_.unlock()) return kStatusEStop;
        out_ += fmt::format("[MSG:Caution: Unlocked]{}", grbl::kEol);
        reported_alarm_.reset();
      }
      // Outside an alarm $X has no effect, and answers ok.
    } else {
      return static_cast<int>(GrblStatus::invalid_statement);
    }
    return 0;
  }

  // Soft reset (0x18, or the operator's reset): motion stops, the planner queue and the
  // receive buffer are flushed, the error lock clears and the banner is sent again. Reset
  // while moving loses position: grbl raises ALARM:3 and stays in alarm until $X.
  void soft_reset(double now_s) {
    const bool was_moving = machine_.reset(now_s);
    if (was_moving) machine_.raise_alarm(GrblAlarm::abort_cycle, now_s);
    report_alarm_change();  // ALARM:3 comes before the banner, as grblHAL prints it
    rx_.clear();
    last_eol_ = 0;
    last_error_ = 0;
    modal_ = {};
    awaiting_dwell_.reset();  // the dwell's line dies unanswered with the reset
    on_connect(now_s);
  }

  // Alarms are watched through the machine's state rather than its events (the process loop
  // consumes those for the log). Each alarm is announced once; clearing it re-arms.
  void report_alarm_change() {
    const auto alarm = machine_.alarm();
    if (!alarm) {
      reported_alarm_.reset();
      return;
    }
    if (reported_alarm_ == alarm) return;
    reported_alarm_ = alarm;
    out_ += fmt::format("ALARM:{}{}", static_cast<int>(*alarm), grbl::kEol);
  }

  // Keeps what `$G` shows; parse_block is the same parser the machine uses.
  void track_modal(const ParseResult& parsed) {
    if (parsed.status != GrblStatus::ok) return;
    const Block& b = parsed.block;
    if (b.motion != MotionMode::none && b.motion != MotionMode::dwell) modal_.motion = b.motion;
    if (b.set_inches) modal_.inches = *b.set_inches;
    if (b.set_relative) modal_.relative = *b.set_relative;
    if (b.set_inverse_time) modal_.inverse_time = *b.set_inverse_time;
    if (b.feed_word) modal_.feed = *b.feed_word;
    if (b.program_end) {  // gc_execute_block's program end: G1 G90 G94
      modal_.motion = MotionMode::linear;
      modal_.relative = modal_.inverse_time = false;
    }
  }

  // grblHAL's LINE_BUFFER_SIZE is 257 with the terminator: longer lines answer error:11.
  static constexpr std::size_t kLineBufferChars = 256;

  Machine& machine_;
  GrblParams params_;
  std::size_t planner_blocks_;
  std::deque<char> rx_;  // the receive ring: bytes not yet taken as lines
  std::string out_;
  ProtocolCounters counters_;
  bool stalled_ = false;
  char last_eol_ = 0;
  int last_error_ = 0;
  std::uint64_t ok_index_ = 0;
  std::optional<GrblAlarm> reported_alarm_;
  grbl::ModalView modal_;
  grbl::StatusReporter reporter_;
  std::optional<std::uint64_t> awaiting_dwell_;  // seq of the dwell whose ok is still due
};

}  // namespace

std::unique_ptr<CncProtocol> make_grbl_protocol(Machine& machine, GrblParams params) {
  return std::make_unique<GrblProtocol>(machine, params);
}

}  // namespace lamina::sim
