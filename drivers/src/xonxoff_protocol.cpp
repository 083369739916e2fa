// XON/XOFF drip feed, Fanuc remote-buffer style: the program goes out as one tape image
// (`%` … `%`), the controller throttles it with DC3 (stop) / DC1 (go on), and after a DC3 it
// may say why it stopped for good: SYN (reset) or NAK (alarm). There are no per-line acks.
//
// Bytes are handed out from one offset into the framed text, so a DC1 resumes exactly at the
// next byte: nothing skipped, nothing sent twice. A DC3 stops hand-out at once; what the
// caller already took (at most chunk_bytes per take_sendable) is the overrun the controller
// must absorb, hence a small chunk.
#include <algorithm>

#include <fmt/format.h>

#include "lamina/drivers/line_protocol.hpp"
#include "realtime_scan.hpp"

namespace lamina::drivers {
namespace {

constexpr char kDc1 = 0x11;  // XON: resume
constexpr char kDc3 = 0x13;  // XOFF: stop sending
constexpr char kNak = 0x15;  // after DC3: alarm
constexpr char kSyn = 0x16;  // after DC3: reset

// ISO 840 / Fanuc tape codes: DC1–DC4 switch the reader and punch; `%` ends the program (the
// rest of the tape is ignored) — allowed only as the program's own first and last lines.
const char* xonxoff_realtime_meaning(unsigned char c) {
  switch (c) {
    case 0x11: return "DC1 (reader on)";
    case 0x12: return "DC2 (punch on)";
    case 0x13: return "DC3 (reader off)";
    case 0x14: return "DC4 (punch off)";
    case '%': return "the end of the program";
    default: return nullptr;
  }
}

class XonXoffProtocol final : public LineProtocol {
 public:
  explicit XonXoffProtocol(XonXoffProtocolSettings s) : settings_(s) {
    settings_.chunk_bytes = std::max<std::size_t>(settings_.chunk_bytes, 1);
  }

  std::string name() const override { return "xonxoff"; }
  std::string handshake() override { return {}; }
  bool handshake_done() const override { return true; }

  std::optional<LinkError> check_lines(const std::vector<std::string>& lines, std::size_t first_index) const override {
    for (std::size_t i = 0; i < lines.size(); ++i) {
      const std::string_view line = strip_cr(lines[i]);
      const bool frame = line == "%" && ((i == 0 && first_index == 0) || i + 1 == lines.size());
      if (frame) continue;
      if (auto bad = detail::refuse_realtime_line(first_index + i, line, xonxoff_realtime_meaning, "drip-fed"))
        return bad;
    }
    return std::nullopt;
  }

  // Lines end in LF (ISO code EOB on a Fanuc). The frame is added only when the program does
  // not open with its own `%`; a program that does is sent exactly as loaded.
  void load(LineSpan span) override {
    first_index_ = span.first_index;
    line_count_ = span.lines.size();
    text_.clear();
    line_ends_.clear();
    const bool framed = !span.lines.empty() && strip_cr(span.lines.front()) == "%";
    const bool add_frame = settings_.send_percent_frame && !framed;
    if (add_frame) text_ += "%\n";
    for (const auto& line : span.lines) {
      text_ += strip_cr(line);
      text_ += '\n';
      line_ends_.push_back(text_.size());  // the line is written once the offset reaches this
    }
    if (add_frame) text_ += "%\n";
    offset_ = 0;
    written_lines_ = reported_lines_ = 0;
    halted_ = false;
  }

  std::string take_sendable(std::size_t max_bytes) override {
    if (halted_ || xoff_ || offset_ >= text_.size() || max_bytes == 0) return {};
    const std::size_t n = std::min({settings_.chunk_bytes, max_bytes, text_.size() - offset_});
    std::string out = text_.substr(offset_, n);
    offset_ += n;
    while (written_lines_ < line_ends_.size() && line_ends_[written_lines_] <= offset_) ++written_lines_;
    return out;
  }

  void halt() override { halted_ = true; }

  std::vector<ProtocolEvent> on_received(std::string_view bytes) override {
    std::vector<ProtocolEvent> events;
    // "Accepted" here means written: the protocol has no acks. The events for lines handed
    // out since the last call are delivered now, before what these bytes say.
    for (; reported_lines_ < written_lines_; ++reported_lines_)
      events.emplace_back(LineAccepted{first_index_ + reported_lines_});
    for (const char c : bytes) {
      switch (c) {
        case kDc3:
          xoff_ = true;
          break;
        case kDc1:
          xoff_ = false;
          break;
        case kSyn:
          halted_ = true;
          events.emplace_back(ControllerReset{after_dc3("SYN: the controller was reset")});
          // Its buffer is gone with the reset: the next job need not wait for a DC1.
          xoff_ = false;
          break;
        case kNak:
          halted_ = true;
          events.emplace_back(ControllerAlarm{0, after_dc3("NAK: the controller raised an alarm")});
          break;
        default:
          break;  // DC2/DC4 (punch on/off) and anything else carry nothing for the sender
      }
    }
    return events;
  }

  // A Fanuc is held, resumed and reset from its panel or through the PLC, not over this line.
  std::string realtime(RealtimeCommand) const override { return {}; }
  std::string clear_error_lock() const override { return {}; }

  bool flow_stopped() const override { return xoff_ && !halted_; }
  std::size_t max_backlog_bytes() const override { return settings_.chunk_bytes; }
  std::size_t lines_sent() const override { return written_lines_; }
  std::size_t lines_accepted() const override { return written_lines_; }
  // Done when the closing `%` is out too: the controller ends the tape image there.
  bool finished() const override { return written_lines_ == line_count_ && offset_ >= text_.size(); }

 private:
  static std::string_view strip_cr(std::string_view line) {
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    return line;
  }
  // SYN/NAK belong after a DC3; without one they still stop the job, but say so.
  std::string after_dc3(std::string_view what) const {
    return xoff_ ? std::string(what) : fmt::format("{} (without the DC3 that should precede it)", what);
  }

  XonXoffProtocolSettings settings_;
  std::string text_;                    // the framed program, as it goes on the wire
  std::vector<std::size_t> line_ends_;  // offset just past each program line's LF
  std::size_t first_index_ = 0, line_count_ = 0;
  std::size_t offset_ = 0;              // next byte to hand out
  std::size_t written_lines_ = 0, reported_lines_ = 0;
  bool xoff_ = false, halted_ = false;  // xoff_: a DC3 came and no DC1 since
};

}  // namespace

std::unique_ptr<LineProtocol> make_xonxoff_protocol(XonXoffProtocolSettings settings) {
  return std::make_unique<XonXoffProtocol>(settings);
}

}  // namespace lamina::drivers
