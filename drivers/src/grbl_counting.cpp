// Grbl character counting (Grbl wiki "Interface": "Streaming Protocol: Character-Counting"):
// every line sent is remembered with its length; each `ok` or `error:N` answers the oldest
// one, and a line goes out only while the remembered lengths plus its own fit in the
// controller's receive buffer. With a window of one line it is plain send-response.
#include <algorithm>
#include <deque>
#include <utility>

#include <fmt/format.h>

#include "grbl_counting.hpp"
#include "grbl_reply.hpp"
#include "realtime_scan.hpp"

namespace lamina::drivers::detail {
namespace {

// grblHAL's real-time commands (its stream drivers pick them off the wire, ahead of the line
// buffer): the legacy ? ! ~ and ctrl-X, and every top-bit byte — overrides 0x90–0x9D, spindle
// stop 0x9E, coolant toggles 0xA0/0xA1, door 0x84, jog cancel 0x85, and others to come. A
// UTF-8 character in a comment (°, Ø, ×) is such bytes too.
const char* grbl_realtime_meaning(unsigned char c) {
  switch (c) {
    case '?': return "the status request";
    case '!': return "a feed hold";
    case '~': return "a cycle start";
    case 0x18: return "a soft reset";
    default: break;
  }
  if (c >= 0x80) return "one of grblHAL's extended real-time commands (overrides, door, jog cancel…)";
  return nullptr;
}

// Classic Grbl (AVR) has a 128-byte receive buffer and no `[OPT:]` rx field.
constexpr std::size_t kClassicGrblRxBytes = 128;
constexpr std::string_view kBuildInfoRequest = "$I\n";

// Whose answer an `ok` / `error:` in the controller's queue is.
enum class Awaiting {
  build_info,   // our `$I`
  line,         // a program line of the loaded span
  locked_line,  // a line sent before an error: grblHAL's error lock refuses it (error:N again)
  alarm_line,   // a line sent before an alarm: refused (error:9) or flushed
  earlier_span, // a line of a span loaded before this one (halted by the operator)
  unlock,       // the empty line of clear_error_lock(), answered `ok`
};

struct InFlight {
  Awaiting what = Awaiting::line;
  std::size_t bytes = 0;  // as it sits in the controller's receive buffer, '\n' included
  std::size_t index = 0;  // program index for lines
};

class CountingProtocol final : public LineProtocol {
 public:
  explicit CountingProtocol(CountingSettings s)
      : settings_(std::move(s)), handshake_done_(!settings_.read_build_info) {}

  std::string name() const override { return settings_.name; }

  std::string handshake() override {
    if (handshake_done_) return {};
    // Callable again after a reset swallowed the first request (the banner drops it).
    in_flight_.push_back({Awaiting::build_info, kBuildInfoRequest.size(), 0});
    build_info_lines_ = 0;
    in_flight_bytes_ += kBuildInfoRequest.size();
    return std::string(kBuildInfoRequest);
  }
  bool handshake_done() const override { return handshake_done_; }

  std::optional<LinkError> check_lines(const std::vector<std::string>& lines, std::size_t first_index) const override {
    for (std::size_t i = 0; i < lines.size(); ++i)
      if (auto bad = refuse_realtime_line(first_index + i, lines[i], grbl_realtime_meaning, "grbl")) return bad;
    return std::nullopt;
  }

  void load(LineSpan span) override {
    // Lines of an earlier span may still await their answers (the controller has them).
    for (auto& f : in_flight_)
      if (f.what == Awaiting::line) f.what = Awaiting::earlier_span;
    span_ = std::move(span);
    next_ = accepted_ = 0;
    halted_ = false;
  }

  std::string take_sendable(std::size_t max_bytes) override {
    std::string out;
    if (halted_ || !handshake_done_) return out;
    const std::size_t window = window_bytes();
    while (next_ < span_.lines.size()) {
      // Sent as loaded but for a trailing CR (we end lines with LF alone). The caller loads no
      // empty lines; one would still work (grblHAL answers it `ok`) but clear an error lock.
      std::string_view line = span_.lines[next_];
      if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
      const std::size_t bytes = line.size() + 1;
      if (!in_flight_.empty()) {
        if (settings_.one_line_in_flight) break;
        if (in_flight_bytes_ + bytes > window) break;
      }
      if (!out.empty() && out.size() + bytes > max_bytes) break;  // the pacer's budget (one line at least)
      // A line longer than the whole window goes alone: the controller refuses it (error:11,
      // line overflow) instead of the stream stalling forever.
      out.append(line);
      out.push_back('\n');
      in_flight_.push_back({Awaiting::line, bytes, span_.first_index + next_});
      in_flight_bytes_ += bytes;
      ++next_;
    }
    return out;
  }

  void halt() override { halted_ = true; }

  std::vector<ProtocolEvent> on_received(std::string_view bytes) override {
    std::vector<ProtocolEvent> events;
    for (const auto& line : splitter_.feed(bytes)) on_line(line, events);
    return events;
  }

  std::string realtime(RealtimeCommand command) const override {
    switch (command) {
      case RealtimeCommand::status: return "?";
      case RealtimeCommand::feed_hold: return "!";
      case RealtimeCommand::resume: return "~";
      case RealtimeCommand::reset: return "\x18";
    }
    return {};
  }
  // grblHAL (protocol.c) keeps refusing G-code after an error until it reads an empty line,
  // a `$` command or a reset; the empty line moves nothing and is answered `ok`.
  std::string clear_error_lock() const override { return "\n"; }
  std::vector<std::string> unlock_lines() const override { return {"$X"}; }

  std::optional<Unanswered> unanswered() const override {
    Unanswered u;
    u.bytes = in_flight_bytes_;
    if (!in_flight_.empty()) u.oldest_line_bytes = in_flight_.front().bytes;
    return u;
  }

  std::size_t lines_sent() const override { return next_; }
  std::size_t lines_accepted() const override { return accepted_; }
  bool finished() const override { return accepted_ == span_.lines.size(); }

 private:
  // The receive buffer as the controller names it (configured, else `[OPT:]`, else 128).
  std::size_t buffer_bytes() const {
    if (settings_.rx_buffer_bytes != 0) return settings_.rx_buffer_bytes;
    if (learned_.rx_buffer_bytes && *learned_.rx_buffer_bytes > 0)
      return static_cast<std::size_t>(*learned_.rx_buffer_bytes);
    return kClassicGrblRxBytes;
  }
  // What it holds: a ring buffer of N bytes keeps one slot empty to tell full from empty
  // (grblHAL's stream drivers and Grbl's serial.c alike; grblHAL's Bf shows at most N − 1
  // free). Filling all N loses the last byte — a line's '\n', merging two lines.
  std::size_t window_bytes() const { return std::max<std::size_t>(1, buffer_bytes() - 1); }

  void on_line(const std::string& line, std::vector<ProtocolEvent>& events) {
    const Reply reply = classify_reply(line);
    switch (reply.kind) {
      case ReplyKind::ok:
      case ReplyKind::error: return on_answer(reply, events);
      case ReplyKind::alarm: return on_alarm(reply, events);
      case ReplyKind::banner: return on_banner(reply, events);
      case ReplyKind::status:
        if (auto status = parse_grbl_status(line)) events.emplace_back(StatusReceived{std::move(*status)});
        else events.emplace_back(ProtocolViolation{fmt::format("malformed status report '{}'", line)});
        return;
      case ReplyKind::info:
        if (!in_flight_.empty() && in_flight_.front().what == Awaiting::build_info) {
          learn_build_info(line, learned_);
          if (line.rfind("[MSG:", 0) != 0) ++build_info_lines_;
        }
        return;  // [MSG:…], [GC:…], $N=…: nothing the stream depends on
      case ReplyKind::unknown:
        events.emplace_back(ProtocolViolation{fmt::format("unrecognised reply '{}'", line)});
        return;
    }
  }

  void on_answer(const Reply& reply, std::vector<ProtocolEvent>& events) {
    if (in_flight_.empty()) {
      events.emplace_back(ProtocolViolation{fmt::format("'{}' with nothing in flight", reply.line)});
      return;
    }
    if (in_flight_.front().what == Awaiting::build_info && reply.kind == ReplyKind::ok && build_info_lines_ == 0) {
      // `$I` prints its build info before its ok; an ok before any of it answers a line of an
      // earlier host that the controller is still draining. Not ours: the handshake waits on.
      return;
    }
    const InFlight answered = in_flight_.front();
    in_flight_.pop_front();
    in_flight_bytes_ -= answered.bytes;
    const bool ok = reply.kind == ReplyKind::ok;
    switch (answered.what) {
      case Awaiting::build_info: {
        // A controller without `$I` answers error:3 or similar: keep the defaults.
        handshake_done_ = true;
        ControllerInfo info = learned_;
        info.rx_buffer_bytes = static_cast<int>(buffer_bytes());  // the size in use (the window is one less)
        events.emplace_back(std::move(info));
        return;
      }
      case Awaiting::line:
        if (ok) {
          ++accepted_;
          events.emplace_back(LineAccepted{answered.index});
        } else {
          events.emplace_back(LineRejected{answered.index, reply.code, error_meaning(reply)});
          stop_after_error();
        }
        return;
      case Awaiting::locked_line:   // error:N repeated by the lock: the same failure, not a new one
      case Awaiting::alarm_line:    // error:9 in alarm
      case Awaiting::earlier_span:  // the job that sent it is over
      case Awaiting::unlock:
        return;
    }
  }

  // The lines behind the refused one are in the controller already; its error lock refuses
  // them (nothing moves) and the caller's clear_error_lock() line follows them.
  void stop_after_error() {
    halted_ = true;
    for (auto& f : in_flight_)
      if (f.what == Awaiting::line) f.what = Awaiting::locked_line;
    in_flight_.push_back({Awaiting::unlock, 1, 0});
    in_flight_bytes_ += 1;
  }

  void on_alarm(const Reply& reply, std::vector<ProtocolEvent>& events) {
    halted_ = true;
    for (auto& f : in_flight_)
      if (f.what == Awaiting::line) f.what = Awaiting::alarm_line;
    events.emplace_back(ControllerAlarm{reply.code, alarm_meaning(reply)});
  }

  // A (re)started controller has an empty receive buffer: whatever was in flight is gone,
  // neither accepted nor refused. Streaming on would skip those lines, so stop.
  void on_banner(const Reply& reply, std::vector<ProtocolEvent>& events) {
    in_flight_.clear();
    in_flight_bytes_ = 0;
    halted_ = true;
    events.emplace_back(ControllerReset{reply.line});
  }

  CountingSettings settings_;
  ReplyLineSplitter splitter_;
  ControllerInfo learned_;
  bool handshake_done_ = false;
  int build_info_lines_ = 0;  // [VER:]/[OPT:]… lines seen since our `$I` went out
  std::deque<InFlight> in_flight_;
  std::size_t in_flight_bytes_ = 0;
  LineSpan span_;
  std::size_t next_ = 0, accepted_ = 0;
  bool halted_ = false;
};

}  // namespace

std::unique_ptr<LineProtocol> make_counting_protocol(CountingSettings settings) {
  return std::make_unique<CountingProtocol>(std::move(settings));
}

}  // namespace lamina::drivers::detail
