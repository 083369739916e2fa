#include "starvation_watch.hpp"

#include <fmt/format.h>

namespace lamina::drivers::detail {

StarvationWatch::StarvationWatch(const std::vector<std::string>& program) {
  waits_.reserve(program.size());
  for (const auto& line : program) waits_.push_back(grbl_line_wait(line));
}

std::optional<Starvation> StarvationWatch::on_reading(const StarvationReading& r) {
  const bool dry = r.water_flowing && r.cnc_state == ControllerState::idle && r.standing_at &&
                   *r.standing_at < waits_.size() && !waits_[*r.standing_at].syncs;
  if (!dry) {
    seen_at_.reset();
    return std::nullopt;
  }
  const std::size_t line = *r.standing_at;
  if (seen_at_ != line) {
    seen_at_ = line;
    seen_since_s_ = r.read_at_s;
  }
  const bool unsent = line >= r.lines_sent_end;
  if (!unsent && r.read_at_s - seen_since_s_ < kConfirmS) return std::nullopt;
  if (unsent)
    return Starvation{true, LinkError{LinkErrorCode::starved,
                                      fmt::format("the controller ran out of program before line {} and stood Idle with "
                                                  "the jet on (the host had not sent that line yet: the host or the line "
                                                  "too slow): held, jet and abrasive off; resume when the cause is gone",
                                                  line + 1)}};
  return Starvation{false, LinkError{LinkErrorCode::timeout,
                                     fmt::format("the controller stalled: it stood Idle with the jet on before line {}, "
                                                 "which it has and did not run (its serial input hung, or a line or an "
                                                 "answer was lost): stopped at once",
                                                 line + 1)}};
}

}  // namespace lamina::drivers::detail
