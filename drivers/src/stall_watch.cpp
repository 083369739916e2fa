#include "stall_watch.hpp"

#include <algorithm>

#include <fmt/format.h>

namespace lamina::drivers::detail {

void StallWatch::load(const std::vector<std::string>& lines, std::size_t first_index) {
  waits_.clear();
  waits_.reserve(lines.size());
  for (const auto& line : lines) waits_.push_back(grbl_line_wait(line));
  first_index_ = first_index;
  idle_since_s_.reset();
}

double StallWatch::dwell_of(std::size_t answered) const {
  return answered < waits_.size() ? waits_[answered].dwell_s : 0;
}

double StallWatch::silence_allowed_s(double silence_timeout_s, std::size_t answered) const {
  return silence_timeout_s + dwell_of(answered);
}

std::optional<LinkError> StallWatch::on_status(const ControllerStatus& status, double now_s, const LinkCounts& counts) {
  if (status.rx_bytes_free) rx_free_when_empty_ = std::max(rx_free_when_empty_.value_or(0), *status.rx_bytes_free);
  if (counts.sent == counts.answered || status.state != ControllerState::idle) {
    idle_since_s_.reset();
    return std::nullopt;
  }
  if (!idle_since_s_ || counts.answered != answered_at_idle_) {
    idle_since_s_ = now_s;
    idle_reports_ = 0;
    answered_at_idle_ = counts.answered;
  }
  ++idle_reports_;
  const double idle_s = now_s - *idle_since_s_;
  if (idle_reports_ < kMinIdleReports || idle_s <= margin_s_ + dwell_of(counts.answered)) return std::nullopt;
  return diagnose(status, counts, idle_s);
}

// Which fault, from the controller's own count of free receive bytes against ours of what it
// should still hold. Its free count when empty is the most it ever reported (grblHAL shows
// size − 1, classic Grbl the size), so `unread` is what sits in its buffer now.
//   unread ≥ our unanswered bytes: it took nothing of what waits — it stopped reading;
//   short by less than the oldest line: bytes were lost on the way, a line never ended;
//   short by a line or more: it took lines and their answers never came.
LinkError StallWatch::diagnose(const ControllerStatus& status, const LinkCounts& counts, double idle_s) const {
  const std::string where = fmt::format("idle for {:.1f} s with {} line(s) unanswered (from line {})", idle_s,
                                        counts.sent - counts.answered, first_index_ + counts.answered + 1);
  if (!status.rx_bytes_free || !counts.unanswered || !rx_free_when_empty_)
    return LinkError{LinkErrorCode::timeout,
                     fmt::format("the controller is {}: an answer was lost or it stopped reading", where)};
  const long unread = std::max(0L, static_cast<long>(*rx_free_when_empty_) - *status.rx_bytes_free);
  const long missing = static_cast<long>(counts.unanswered->bytes) - unread;
  if (missing <= 0)
    return LinkError{LinkErrorCode::timeout,
                     fmt::format("the controller stalled: {}, all {} byte(s) of them unread in its receive buffer",
                                 where, unread)};
  if (missing < static_cast<long>(counts.unanswered->oldest_line_bytes))
    return LinkError{LinkErrorCode::protocol_error,
                     fmt::format("bytes lost on the line: the controller is {}, {} byte(s) short of them in its "
                                 "receive buffer (a line that never ended)",
                                 where, missing)};
  return LinkError{LinkErrorCode::protocol_error,
                   fmt::format("acknowledgement lost: the controller is {}, and has taken {} byte(s) of them from "
                               "its receive buffer without answering",
                               where, missing)};
}

}  // namespace lamina::drivers::detail
