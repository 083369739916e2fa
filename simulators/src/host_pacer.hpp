#pragma once
// --pace-to-host: the simulated machine runs at --time-scale only while the host keeps ahead of
// it. A test machine compresses time (40x, 50x) to cut a sheet in seconds; on a loaded CI box a
// sanitized host then pauses for 100 ms — nothing at a real machine, where the planner's blocks
// last seconds — and the compressed machine runs dry with the jet on. That starvation is the
// test's, not the host's. Paced, the clock drops to real time at the instant the controller holds
// both under `low_lead_s` of motion and at most half its planner, while the host owes it more; it
// goes back to the time scale once the planner is ¾ full or holds `high_lead_s` again, or the
// program stops on its own (a sync, a dwell, a hold). A host that cannot feed the machine at real
// time still starves it, as it would a real one. Pure: the caller brings the simulated time and
// the machine's state.
#include <algorithm>
#include <cstddef>
#include <optional>

namespace lamina::sim {

struct HostPacerParams {
  double low_lead_s = 1.0;   // simulated s of motion left: below it (and half the planner), real time
  double high_lead_s = 2.0;  // … at or above it, the time scale again
};

// What the controller holds: the motion still to run and its planner's blocks.
struct ControllerLead {
  double ahead_s = 0;          // simulated s of motion, the running block's rest included
  double until_half_s = 0;     // simulated s until at most half the planner's blocks are left
  std::size_t blocks = 0;      // timed blocks queued, the running one included
  std::size_t capacity = 1;    // the planner's blocks
};

// What the clock should do from now on: run at `scale`, and — when running fast towards the
// low mark — drop to `slow_scale` at simulated time `slow_from_s` (the caller's clock may pass
// that instant between two looks, so the knee is exact whatever the loop's latency).
struct PaceDecision {
  double scale = 1;
  std::optional<double> slow_from_s;
  double slow_scale = 1;
};

class HostPacer {
 public:
  explicit HostPacer(HostPacerParams params = {}) : params_(params) {}

  // now_s: simulated time; host_owes: the program runs on and only new lines keep it going;
  // ceiling: the time scale asked for.
  PaceDecision decide(double now_s, const ControllerLead& lead, bool host_owes, double ceiling) {
    const double slow = std::min(1.0, ceiling);
    const bool caught_up = lead.blocks * 4 >= lead.capacity * 3 || lead.ahead_s >= params_.high_lead_s;
    const bool behind = lead.blocks * 2 <= lead.capacity && lead.ahead_s < params_.low_lead_s;
    if (!host_owes || caught_up) slowed_ = false;
    else if (behind) mark_slowed();
    if (slowed_) return {slow, std::nullopt, slow};
    if (!host_owes) return {ceiling, std::nullopt, slow};
    // Both marks must be passed: the later of the two instants, never before now.
    const double knee_in_s = std::max({0.0, lead.until_half_s, lead.ahead_s - params_.low_lead_s});
    return {ceiling, now_s + knee_in_s, slow};
  }
  // The clock passed the knee decide() named: the pacer is slowed from there on.
  void slowed_at_knee() { mark_slowed(); }
  bool slowed() const { return slowed_; }
  unsigned slowdowns() const { return slowdowns_; }

 private:
  void mark_slowed() {
    if (!slowed_) ++slowdowns_;
    slowed_ = true;
  }
  HostPacerParams params_;
  bool slowed_ = false;
  unsigned slowdowns_ = 0;
};

}  // namespace lamina::sim
