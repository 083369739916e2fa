#pragma once
// The streamer's stall rule, without I/O: told each status report, the time (an argument, as
// sim::Machine takes it) and what the protocol has sent and had answered; says when a
// controller that stands Idle with lines unanswered has stopped working, and which fault it
// is. A controller answers most lines when they enter its planner, but a dwell, a jet change
// or a program end only once the motion before it is done (line_wait.hpp): Idle while such a
// line waits is work, allowed its dwell plus the margin.
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "lamina/drivers/controller_status.hpp"
#include "lamina/drivers/line_protocol.hpp"
#include "lamina/drivers/line_wait.hpp"
#include "lamina/drivers/link_error.hpp"

namespace lamina::drivers::detail {

struct LinkCounts {  // of the loaded span, as the protocol counts them
  std::size_t sent = 0;
  std::size_t answered = 0;
  std::optional<LineProtocol::Unanswered> unanswered;  // bytes in the controller by our count
};

class StallWatch {
 public:
  static constexpr int kMinIdleReports = 3;  // a report or two may overtake an answer on the wire

  explicit StallWatch(double margin_s) : margin_s_(margin_s) {}

  // A new span: how the controller answers each of its lines. `first_index` numbers them.
  void load(const std::vector<std::string>& lines, std::size_t first_index);
  // A status report at `now_s`. Returns the error that stops the job once the controller has
  // stood Idle, in at least three reports in a row with no answer between, for longer than the
  // margin plus the dwell of the oldest unanswered line.
  std::optional<LinkError> on_status(const ControllerStatus& status, double now_s, const LinkCounts& counts);
  // How long silence may last with lines in flight: the timeout plus that dwell.
  double silence_allowed_s(double silence_timeout_s, std::size_t answered) const;

 private:
  double dwell_of(std::size_t answered) const;
  LinkError diagnose(const ControllerStatus& status, const LinkCounts& counts, double idle_s) const;

  double margin_s_;
  std::vector<LineWait> waits_;
  std::size_t first_index_ = 0;
  std::optional<double> idle_since_s_;
  int idle_reports_ = 0;
  std::size_t answered_at_idle_ = 0;
  std::optional<int> rx_free_when_empty_;  // the most free receive bytes ever reported
};

}  // namespace lamina::drivers::detail
