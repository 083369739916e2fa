#pragma once
// What a feed hold does to the jet (issue 16, item 1), sans-IO: time is an argument.
//
// A held machine stands still; a standing abrasive jet drills the part and the bed. So once
// the controller reports the hold complete (grbl `Hold:0`, the PLC's "hold" lamp; not
// `Hold:1`, still decelerating along the path with the jet cutting), the jet goes off through
// the PLC with the abrasive feed; the pump stays pressurised. The operator's resume opens the
// jet again in the kerf at the hold point, waits for it to stabilise, then continues the motion.
// A hold longer than the limit becomes a stop (the job's resume point is set); a machine that
// leaves the hold by itself (cycle start on its own panel) while the jet is off is stopped too:
// it would move without cutting, and resume only through Lamina re-opens the jet first.
//
// Whoever asked for the hold (the operator through Lamina, the PLC's hold button, the
// controller's own panel) the rule is the same: it watches the state, not the request.
#include <optional>

#include "lamina/drivers/controller_status.hpp"
#include "lamina/drivers/link_error.hpp"

namespace lamina::drivers::detail {

struct HoldGuardSettings {
  double hold_limit_s = 600;   // held longer than this (from the hold completing): a stop
  double jet_restart_s = 1.0;  // jet open again → motion continues (the jet stabilises)
};

enum class HoldAction {
  none,
  jet_off,         // the machine stands in a hold: jet and abrasive off through the PLC
  jet_on,          // the operator resumes: jet and abrasive on (then wait jet_restart_s)
  cycle_start,     // the jet has had its restart time: continue the motion
  stop,            // stop the job with stop_reason()
  starved_hold,    // the machine ran dry with the jet on: feed hold, then jet and abrasive off
};

class HoldGuard {
 public:
  explicit HoldGuard(HoldGuardSettings settings) : settings_(settings) {}

  // The controller's state as last reported (the link's status, or the PLC's lamps).
  HoldAction on_state(ControllerState state, double now_s);
  // The operator asked to continue. Returns what to do now: jet_on when the jet was turned off
  // by the hold (then on_state() says cycle_start after the restart time), cycle_start when it
  // was never off (a hold still decelerating, or no jet to restore).
  HoldAction on_resume_request(double now_s);
  // The PLC has taken the jet-on (restore_jet returned): the restart time counts from here, not
  // from the request. A busy PLC or bus may take a while to open the jet, and the jet must have
  // its whole restart time before the motion (the simulator's log once showed 499.9 ms of 500).
  void on_jet_opened(double now_s);
  // The machine stands Idle mid-program with the water on (starvation_watch.hpp): starved_hold,
  // once, unless a hold already has the jet off. It is then held as after any hold: the
  // operator's resume opens the jet and continues. An Idle machine counts as standing in it
  // (a controller may not enter Hold from Idle), and one that moves before the resume, even
  // decelerating into the hold (lines that reached it first), moved with the jet off: a stop.
  HoldAction on_starved(double now_s);

  bool jet_off_by_hold() const { return jet_off_; }
  const std::optional<LinkError>& stop_reason() const { return stop_reason_; }

 private:
  HoldAction stop(LinkError why);

  HoldGuardSettings settings_;
  std::optional<double> held_since_s_;     // when the hold completed (Hold:0)
  bool jet_off_ = false;                   // we turned the jet off for this hold
  std::optional<double> restart_at_s_;     // resuming: the jet is on, the motion waits until then
  bool cycle_started_ = false;             // resuming: cycle start sent, waiting to leave the hold
  bool starved_ = false;                   // this hold is a starvation's
  std::optional<LinkError> stop_reason_;
};

}  // namespace lamina::drivers::detail
