#pragma once
// Simulated time: wall-clock seconds since start times a scale (--time-scale), which the control
// socket may change while the machine runs (`time-scale K`). The clock stays continuous across a
// change, so no move jumps; the scale holds from the change on. Read from the PLC's thread too.
#include <algorithm>
#include <chrono>
#include <mutex>

namespace lamina::sim {

class SimClock {
 public:
  explicit SimClock(double scale) : start_(std::chrono::steady_clock::now()), scale_(scale) {}

  double wall_s() const { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count(); }
  double sim_at(double wall_s) const {
    std::lock_guard lock(mutex_);
    return sim_base_s_ + (wall_s - wall_base_s_) * scale_;
  }
  double sim_s() const { return sim_at(wall_s()); }
  double scale() const {
    std::lock_guard lock(mutex_);
    return scale_;
  }
  void set_scale(double scale) {
    const double wall = wall_s();
    std::lock_guard lock(mutex_);
    sim_base_s_ += (wall - wall_base_s_) * scale_;
    wall_base_s_ = wall;
    scale_ = scale;
  }
  // From simulated time `at_sim_s` on, run at `scale`: the clock is rebased where it reached
  // at_sim_s, so a change noticed late (the loop slept past it) still happens at its instant.
  // at_sim_s is not before the last change.
  void set_scale_from(double at_sim_s, double scale) {
    std::lock_guard lock(mutex_);
    at_sim_s = std::max(at_sim_s, sim_base_s_);
    wall_base_s_ += (at_sim_s - sim_base_s_) / scale_;
    sim_base_s_ = at_sim_s;
    scale_ = scale;
  }

 private:
  std::chrono::steady_clock::time_point start_;
  mutable std::mutex mutex_;
  double scale_;
  double sim_base_s_ = 0, wall_base_s_ = 0;
};

}  // namespace lamina::sim
