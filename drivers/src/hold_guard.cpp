#include "hold_guard.hpp"

#include <fmt/format.h>

namespace lamina::drivers::detail {
namespace {

bool moving(ControllerState s) {
  return s == ControllerState::run || s == ControllerState::jog || s == ControllerState::home;
}

}  // namespace

HoldAction HoldGuard::stop(LinkError why) {
  stop_reason_ = std::move(why);
  return HoldAction::stop;
}

HoldAction HoldGuard::on_state(ControllerState state, double now_s) {
  if (stop_reason_) return HoldAction::none;
  if (moving(state) || (starved_ && state == ControllerState::hold_pending)) {
    if (jet_off_ && !cycle_started_)
      return stop({LinkErrorCode::left_hold_without_jet,
                   starved_ ? "the machine moved on after it ran dry, before the hold took, with the jet off: "
                              "stopped; resume from the contour's start"
                            : "the machine left the feed hold by itself (its own cycle start?) while the jet was off: "
                              "stopped; resume through Lamina, which opens the jet first"});
    held_since_s_.reset();  // the hold is over (or there was none)
    jet_off_ = cycle_started_ = starved_ = false;
    restart_at_s_.reset();
    return HoldAction::none;
  }
  const bool standing = state == ControllerState::hold || (starved_ && state == ControllerState::idle);
  if (!standing) return HoldAction::none;  // decelerating, idle, alarm, door: not ours
  if (!held_since_s_) held_since_s_ = now_s;
  if (restart_at_s_) {
    if (now_s < *restart_at_s_) return HoldAction::none;
    restart_at_s_.reset();
    cycle_started_ = true;
    return HoldAction::cycle_start;
  }
  if (cycle_started_) return HoldAction::none;  // the cycle start is on its way
  if (!jet_off_) {
    jet_off_ = true;
    return HoldAction::jet_off;
  }
  if (now_s - *held_since_s_ > settings_.hold_limit_s)
    return stop({LinkErrorCode::held_too_long,
                 fmt::format("held for more than {:.0f} s ([cut] hold_limit_s): the job is stopped, resume from the "
                             "contour's start",
                             settings_.hold_limit_s)});
  return HoldAction::none;
}

HoldAction HoldGuard::on_starved(double now_s) {
  if (stop_reason_ || jet_off_ || restart_at_s_ || cycle_started_) return HoldAction::none;
  starved_ = jet_off_ = true;
  held_since_s_ = now_s;
  return HoldAction::starved_hold;
}

HoldAction HoldGuard::on_resume_request(double now_s) {
  if (stop_reason_ || restart_at_s_ || cycle_started_) return HoldAction::none;
  if (!jet_off_) return HoldAction::cycle_start;
  restart_at_s_ = now_s + settings_.jet_restart_s;
  return HoldAction::jet_on;
}

void HoldGuard::on_jet_opened(double now_s) {
  if (restart_at_s_ && !cycle_started_) restart_at_s_ = now_s + settings_.jet_restart_s;
}

}  // namespace lamina::drivers::detail
