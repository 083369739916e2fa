// The simulated CNC's executor: queue, modal state, feed hold, alarms, events.
//
// Behaviour where the header leaves room (all Grbl-like unless said):
// - Only moves that go somewhere occupy the planner, as only motion does in grblHAL; dwells and
//   zero-time lines still queue in program order (no capacity) so each one is logged when the
//   machine reaches it. The running block keeps its planner slot until it finishes (Grbl frees
//   a block when it is done), so free_blocks() counts it.
// - A dwell runs after the drain its planner sync asks for, as grblHAL's mc_dwell
//   (protocol_buffer_synchronize, then delay_sec): nothing else is planned while it runs, so Bf
//   shows every block free. Its `ok` waits for its end — that is the grbl protocol's business.
// - A block starts when the previous one ended, or at its submit time if the queue had run dry,
//   or at the cycle-start time after a hold.
// - Feed hold in Idle enters Hold at once (Grbl 1.1 too); lines sent then wait for `~`. A hold
//   during a dwell stops the dwell clock at once (no motion to decelerate). Cycle start while
//   still decelerating is ignored, as in Grbl (hold must be complete).
// - Modal changes (G20, G91, F…) act when the line is accepted, like Grbl's parser state; the
//   jet M-codes and M2/M30 act when their block starts executing.
// - M2/M30 (Grbl's program end): G1, G90, G94, jet, spindle and coolant off; units and F stay
//   (Grbl keeps them).
// - reset() returns true only when an axis was moving (cruising or decelerating), not during a
//   dwell or a completed hold.
// - Soft-limit alarms report the seq the refused line would have had (accepted_blocks() + 1),
//   which is its program line when a sender streams a program line for line.
// - A timed line submitted without room is refused with overflow and nothing changes: the
//   protocols ask has_room_for first and keep the line in their receive buffer meanwhile.
#include "machine.hpp"

#include <algorithm>
#include <cmath>

#include "machine_plan.hpp"

namespace lamina::sim {

Machine::Machine(MachineConfig config) : config_(std::move(config)) {}

namespace {
// Takes time (a move or a dwell): the machine is busy with the program while it runs.
bool is_timed(const detail::PlannedBlock& b) { return b.duration_s > 0; }
// Occupies a planner slot: grblHAL plans a block only for a move that goes somewhere (an empty
// move is dropped by plan_buffer_line); a dwell runs in mc_dwell, outside the planner.
bool occupies_planner(const detail::PlannedBlock& b) { return is_timed(b) && b.kind != MotionMode::dwell; }
// grblHAL synchronises with the planner (protocol_buffer_synchronize) before a spindle — here
// the jet — change (spindle_sync), a coolant change (coolant_sync), a program end and a dwell
// (mc_dwell): the line waits unanswered until every motion before it is done, so the machine
// stands still when the jet turns on or off.
bool syncs(const detail::PlannedBlock& b) {
  return b.jet_on.has_value() || b.spindle.has_value() || b.coolant.has_value() || b.program_end ||
         b.kind == MotionMode::dwell;
}
void apply_coolant(CoolantCommand c, Accessories& a) {
  switch (c) {
    case CoolantCommand::mist: a.mist = true; break;
    case CoolantCommand::flood: a.flood = true; break;
    case CoolantCommand::off: a.mist = a.flood = false; break;
  }
}
}  // namespace

Machine::Planned Machine::plan_line(std::string_view line) const {
  Planned out;
  out.modal = modal_;
  const ParseResult parsed = parse_block(line, config_.parse);
  out.status = parsed.status;
  if (parsed.status != GrblStatus::ok || parsed.block.percent) return out;
  detail::PlannedBlock planned;
  out.status = detail::plan_block(parsed.block, out.modal, planned_pos_, config_, planned);
  if (out.status != GrblStatus::ok) return out;
  if (planned.program_end) {
    // Grbl's program end resets these in the parser state as the line is read.
    out.modal.motion = MotionMode::linear;
    out.modal.relative = false;
    if (out.modal.inverse_time) out.modal.feed_mm_per_min.reset();
    out.modal.inverse_time = false;
  }
  out.block = std::move(planned);
  return out;
}

GrblStatus Machine::submit_line(std::string_view line, double now_s) {
  advance(now_s);
  if (alarm_) return GrblStatus::system_gc_lock;
  Planned p = plan_line(line);
  if (p.status != GrblStatus::ok) return p.status;
  if (!p.block) return GrblStatus::ok;  // `%`
  detail::PlannedBlock& planned = *p.block;
  // The soft-limit check comes before the wait for a free block, as in grblHAL's mc_line: a
  // bad target alarms at once even with the planner full.
  if (config_.soft_limits && !detail::within_soft_limits(planned, config_)) {
    alarm_stop(GrblAlarm::soft_limit, now_s, accepted_ + 1);
    return GrblStatus::soft_limit;
  }
  if (occupies_planner(planned) && !has_room()) return GrblStatus::overflow;
  modal_ = p.modal;
  planned.seq = ++accepted_;
  planned.line = std::string(line);
  planned.submit_s = now_s;
  planned_pos_ = planned.target;
  if (!program_running_) moved_in_program_ = false;
  program_running_ = true;  // from the first block after Idle until M2/M30 executes
  starved_ = false;
  draining_for_sync_ = false;
  pending_stop_.reset();  // a block at the instant the queue ran dry: no stop after all
  queue_.push_back(std::move(planned));
  advance(now_s);
  return GrblStatus::ok;
}

bool Machine::has_room() const { return free_blocks() > 0; }
bool Machine::has_room_for(std::string_view line) const {
  if (alarm_) return true;
  const Planned p = plan_line(line);
  if (p.status != GrblStatus::ok || !p.block) return true;  // answered without a block
  if (config_.soft_limits && !detail::within_soft_limits(*p.block, config_)) return true;
  if (syncs(*p.block) && queued_blocks() > 0) {
    draining_for_sync_ = true;  // the queue runs dry on purpose: no starvation
    return false;
  }
  return has_room() || !occupies_planner(*p.block);
}
std::size_t Machine::free_blocks() const {
  const std::size_t used = queued_timed_blocks();
  return config_.planner_blocks > used ? config_.planner_blocks - used : 0;
}
std::size_t Machine::queued_blocks() const { return queue_.size() + (running_ ? 1 : 0); }
std::size_t Machine::queued_timed_blocks() const {
  const auto queued = std::count_if(queue_.begin(), queue_.end(), occupies_planner);
  return static_cast<std::size_t>(queued) + (running_ && occupies_planner(running_->block) ? 1 : 0);
}
std::size_t Machine::planner_blocks() const { return config_.planner_blocks; }
double Machine::motion_ahead_s(double now_s) const {
  double ahead_s = 0;
  if (running_) ahead_s = std::max(0.0, phase_end_s(*running_) - now_s);
  for (const auto& b : queue_) ahead_s += b.duration_s;
  return ahead_s;
}
double Machine::time_until_blocks_left(double now_s, std::size_t blocks) const {
  std::size_t left = queued_timed_blocks();
  if (left <= blocks) return 0;
  double until_s = 0;
  if (running_ && occupies_planner(running_->block)) {
    until_s = std::max(0.0, phase_end_s(*running_) - now_s);
    if (--left <= blocks) return until_s;
  }
  for (const auto& b : queue_) {
    until_s += b.duration_s;
    if (occupies_planner(b) && --left <= blocks) break;
  }
  return until_s;
}
bool Machine::runs_on_host_lines() const {
  return running_ && running_->phase == Phase::cruise && program_running_ && !held_ && !alarm_ &&
         !draining_for_sync_ && !dwelling();
}

double Machine::fraction_at(const Running& r, double now_s) const {
  const double dt = std::max(0.0, now_s - r.seg_t0_s);
  switch (r.phase) {
    case Phase::cruise:
      if (r.block.duration_s <= 0) return 1;
      return std::min(1.0, r.seg_s0 + dt / r.block.duration_s);
    case Phase::decel: {
      const double tau = std::min(dt, r.decel_tau_s);
      const double a = config_.hold_decel_mm_per_s2;
      return std::min(r.decel_s_end, r.seg_s0 + (r.decel_v * tau - a * tau * tau / 2) / r.block.path_length);
    }
    case Phase::stopped: return r.seg_s0;
  }
  return r.seg_s0;
}

// When the current phase ends (cruise: block done; decel: stopped or block done). Stopped: never.
double Machine::phase_end_s(const Running& r) const {
  switch (r.phase) {
    case Phase::cruise: return r.seg_t0_s + (1 - r.seg_s0) * r.block.duration_s;
    case Phase::decel: return r.seg_t0_s + r.decel_tau_s;
    case Phase::stopped: break;
  }
  return INFINITY;
}

void Machine::advance(double now_s) {
  run_queue(now_s);
  confirm_pending_stop(now_s);
}

void Machine::run_queue(double now_s) {
  while (!alarm_) {
    if (!running_) {
      if (held_ || queue_.empty()) return;
      start_next(std::max(last_end_s_, queue_.front().submit_s));
      continue;
    }
    Running& r = *running_;
    const double end_s = phase_end_s(r);
    if (end_s > now_s) return;
    if (r.phase == Phase::decel && r.decel_s_end < 1) {
      r.phase = Phase::stopped;  // hold complete part-way through the block
      r.seg_t0_s = end_s;
      r.seg_s0 = r.decel_s_end;
      return;
    }
    finish_running(end_s);
  }
}

void Machine::start_next(double t_s) {
  Running r;
  r.block = std::move(queue_.front());
  queue_.pop_front();
  r.t_start_s = t_s;
  r.seg_t0_s = t_s;
  if (config_.alarm_at_seq && r.block.seq == *config_.alarm_at_seq) {
    // Fault injection: the block never moves; it is logged cut short, then the alarm stops all.
    const std::uint64_t seq = r.block.seq;
    r.block.target = pos_;
    r.block.start = pos_;
    r.block.duration_s = 0;
    running_ = std::move(r);
    alarm_stop(config_.alarm_at_seq_code, t_s, seq);
    return;
  }
  if (r.block.jet_on) jet_ = *r.block.jet_on;
  if (r.block.spindle) accessories_.spindle = *r.block.spindle;
  if (r.block.coolant) apply_coolant(*r.block.coolant, accessories_);
  if (r.block.program_end) {
    jet_ = false;
    accessories_ = {};  // grblHAL's program end: spindle_all_off, coolant off
    ++program_ends_;
    program_running_ = !queue_.empty();  // lines already queued behind M2 start the next program
  }
  running_ = std::move(r);
}

void Machine::finish_running(double t_s) {
  const detail::PlannedBlock& b = running_->block;
  const std::uint64_t seq = b.seq;
  const bool timed = is_timed(b), sync = syncs(b);
  const double started_s = running_->t_start_s;
  events_.push_back(ExecutedBlock{b.seq, b.line, b.start, b.target, jet_, running_->t_start_s, t_s, true});
  pos_ = b.target;
  last_end_s_ = t_s;
  ++executed_;
  running_.reset();
  if (timed) {
    moved_in_program_ = true;
    last_motion_end_s_ = t_s;
  }
  // Starvation = the program stopped because no block was ready. The machine was going until
  // now if this block moved or dwelt, was a jet change (after it the program goes on), or was
  // a zero-time line queued behind a move that ended at this instant. A stop the program asks
  // for — waiting for this drain (the planner sync) — is not one. Whether the queue really ran
  // dry is decided when the next block comes: a line submitted at this very instant (the one
  // behind a sync, taken in the same pass) means it did not.
  const bool going = timed || sync || started_s <= last_motion_end_s_;
  if (queue_.empty() && going && program_running_ && moved_in_program_ && !held_ && !alarm_ && !starved_ &&
      !draining_for_sync_)
    pending_stop_ = StarvationEvent{t_s, seq};
}

// A stop noted by finish_running becomes starvation once time has passed with nothing queued.
void Machine::confirm_pending_stop(double now_s) {
  if (!pending_stop_ || now_s <= pending_stop_->t_s) return;
  if (queue_.empty() && !running_ && !held_ && !alarm_ && program_running_ && !starved_) {
    events_.push_back(*pending_stop_);
    starved_ = true;
    ++starvations_;
  }
  pending_stop_.reset();
}

void Machine::stop_running(double t_s) {
  if (!running_) return;
  const detail::PlannedBlock& b = running_->block;
  pos_ = detail::interpolate(b, fraction_at(*running_, t_s));
  events_.push_back(ExecutedBlock{b.seq, b.line, b.start, pos_, jet_, running_->t_start_s, t_s, false});
  ++executed_;
  running_.reset();
}

void Machine::reset_modal() {
  modal_ = detail::ModalState{};
  jet_ = false;
  accessories_ = {};
  held_ = false;
  program_running_ = false;
  moved_in_program_ = false;
  starved_ = false;
  draining_for_sync_ = false;
  pending_stop_.reset();
}

void Machine::alarm_stop(GrblAlarm code, double t_s, std::uint64_t seq) {
  stop_running(t_s);
  queue_.clear();
  planned_pos_ = pos_;
  last_end_s_ = t_s;
  reset_modal();
  alarm_ = code;
  events_.push_back(AlarmEvent{t_s, code, seq});
}

void Machine::feed_hold(double now_s) {
  advance(now_s);
  if (alarm_ || held_) return;
  held_ = true;
  if (!running_) return;  // Idle (or between blocks): Hold at once
  Running& r = *running_;
  const double s = fraction_at(r, now_s);
  r.seg_t0_s = now_s;
  r.seg_s0 = s;
  if (r.block.kind == MotionMode::dwell || r.block.path_length <= 0) {
    r.phase = Phase::stopped;
    return;
  }
  // Decelerate from the block's speed: v²/2a to stop, or what is left of the block if less
  // (then the block ends still moving, and the hold completes there).
  const double v = r.block.path_length / r.block.duration_s;
  const double a = config_.hold_decel_mm_per_s2;
  const double left = (1 - s) * r.block.path_length;
  const double stop = v * v / (2 * a);
  r.phase = Phase::decel;
  r.decel_v = v;
  if (stop < left) {
    r.decel_tau_s = v / a;
    r.decel_s_end = s + stop / r.block.path_length;
  } else {
    r.decel_tau_s = (v - std::sqrt(std::max(0.0, v * v - 2 * a * left))) / a;
    r.decel_s_end = 1;
  }
  advance(now_s);
}

void Machine::cycle_start(double now_s) {
  advance(now_s);
  if (alarm_ || !held_) return;
  if (running_ && running_->phase == Phase::decel) return;  // hold not complete yet
  held_ = false;
  if (running_) {
    running_->phase = Phase::cruise;
    running_->seg_t0_s = now_s;
  } else {
    last_end_s_ = std::max(last_end_s_, now_s);
    if (queue_.empty() && program_running_ && moved_in_program_ && !starved_) {
      // Resumed with nothing to run: the program is starving from now.
      events_.push_back(StarvationEvent{now_s, accepted_});
      starved_ = true;
      ++starvations_;
    }
  }
  advance(now_s);
}

bool Machine::reset(double now_s) {
  advance(now_s);
  const bool moving = running_ && running_->block.kind != MotionMode::dwell &&
                      running_->block.path_length > 0 && running_->phase != Phase::stopped;
  stop_running(now_s);
  queue_.clear();
  planned_pos_ = pos_;
  last_end_s_ = now_s;
  reset_modal();  // an alarm stays latched: it needs $X (or the e-stop released and $X)
  return moving;
}

void Machine::raise_alarm(GrblAlarm code, double now_s) {
  advance(now_s);
  alarm_stop(code, now_s, running_ ? running_->block.seq : 0);
}

bool Machine::unlock() {
  if (estop_) return false;
  alarm_.reset();
  return true;
}

void Machine::set_estop(bool pressed, double now_s) {
  if (pressed && !estop_) raise_alarm(GrblAlarm::estop, now_s);
  estop_ = pressed;
}

MachineState Machine::state() const {
  if (alarm_) return MachineState::alarm;
  if (held_) return running_ && running_->phase == Phase::decel ? MachineState::hold_pending : MachineState::hold;
  if (running_ || !queue_.empty()) return MachineState::run;
  return MachineState::idle;
}

AxisValues Machine::position(double now_s) const {
  if (!running_) return pos_;
  return detail::interpolate(running_->block, fraction_at(*running_, now_s));
}

double Machine::feed_mm_per_min(double now_s) const {
  if (!running_ || running_->phase == Phase::stopped || fraction_at(*running_, now_s) >= 1) return 0;
  return running_->block.feed_mm_per_min;
}

// grblHAL's Ln is the current planner block's: none while dwelling (mc_dwell plans nothing).
std::optional<std::int64_t> Machine::line_number() const {
  if (!running_ || running_->block.kind == MotionMode::dwell) return std::nullopt;
  return running_->block.line_number;
}

bool Machine::dwelling() const { return running_ && running_->block.kind == MotionMode::dwell; }
bool Machine::pending(std::uint64_t seq) const {
  if (running_ && running_->block.seq == seq) return true;
  return std::any_of(queue_.begin(), queue_.end(), [seq](const detail::PlannedBlock& b) { return b.seq == seq; });
}
void Machine::expect_line_after_dwell() {
  if (dwelling()) draining_for_sync_ = true;
}
Accessories Machine::accessories() const { return accessories_; }
std::uint64_t Machine::program_ends() const { return program_ends_; }

std::uint64_t Machine::accepted_blocks() const { return accepted_; }
std::uint64_t Machine::executed_blocks() const { return executed_; }
std::uint64_t Machine::starvation_count() const { return starvations_; }
bool Machine::jet_commanded() const { return jet_; }
std::optional<GrblAlarm> Machine::alarm() const { return alarm_; }

std::vector<MachineEvent> Machine::take_events() {
  std::vector<MachineEvent> out;
  out.swap(events_);
  return out;
}

}  // namespace lamina::sim
