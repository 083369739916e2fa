#pragma once
// A machine that runs out of program mid-cut (issue 16, fault campaign round 2), sans-IO: the
// PLC's readings and the time in, a verdict out.
//
// A controller stands Idle between blocks only when it has nothing to run: its queue ran dry
// because the host (a stalled thread, a slow disk), the line (short segments at a high feed) or
// its own serial task did not keep it fed. With the water flowing that is a standstill that
// drills the part, as a hold's is, and it gets the hold's answer: feed hold, jet and abrasive
// off, the operator's resume (hold_guard.hpp). Judged from the PLC's view, which its own thread
// keeps fresh even when the link's thread is the one stalled: the CNC's state lamps, its jet
// output and the valve, and its executed-block count, which names the block it stands at.
// Standing Idle is the controller's work, not starvation, while that block is a dwell or
// another line it runs only once the motion before it is done (line_wait.hpp: grblHAL reports
// Idle through a G4), and past the program's end.
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "lamina/drivers/controller_status.hpp"
#include "lamina/drivers/line_wait.hpp"
#include "lamina/drivers/link_error.hpp"

namespace lamina::drivers::detail {

struct StarvationReading {
  ControllerState cnc_state = ControllerState::unknown;  // the PLC's lamps
  bool water_flowing = false;                             // the CNC's jet output ∧ the valve's consent
  std::optional<std::size_t> standing_at;  // program index of the block it runs next (executed count)
  std::size_t lines_sent_end = 0;          // program index one past the last line the host sent
  double read_at_s = 0;                    // when the PLC was read
};

struct Starvation {
  // The host had not sent the block: the link is sound, the stream goes on when the cause is
  // gone — a hold (code starved). Else the controller has the block and does not run it: its
  // input hung, or a line or an answer was lost — a stop now (code timeout), which the link's
  // stall rule would make only after its margin with the water on all along.
  bool host_behind = false;
  LinkError why;
};

class StarvationWatch {
 public:
  // Two readings this far apart at the same block confirm a controller that has its next line
  // and does not run it (between a dwell's end and the next block there are microseconds).
  static constexpr double kConfirmS = 0.02;

  explicit StarvationWatch(const std::vector<std::string>& program);

  // Once the machine is seen standing dry with the water on, what it is; nullopt else.
  std::optional<Starvation> on_reading(const StarvationReading& reading);

 private:
  std::vector<LineWait> waits_;
  std::optional<std::size_t> seen_at_;  // the block of the last dry reading…
  double seen_since_s_ = 0;             // …first seen then
};

}  // namespace lamina::drivers::detail
