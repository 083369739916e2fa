#pragma once
// The simulated CNC's motion side: modal state, a finite planner queue, a time model, soft
// limits, feed hold / resume / reset, alarms and the record of every executed block.
// Pure and single-threaded: every call takes the simulated time `now_s` (seconds since the
// simulator started, already multiplied by --time-scale); nothing here reads a clock.
#include <cstdint>
#include <deque>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "gcode_block.hpp"

namespace lamina::sim {

struct MachineConfig {
  // The travel of config/sim-machine.toml (the cell config/machine.toml describes, pivot
  // coordinates included: a tilted head's pivot goes past the table on every side), so a plain
  // lamina-sim runs Lamina's own programs. MachineDefaults.MatchTheSimMachineFile keeps them equal.
  AxisValues soft_min{-200, -200, -200, -120, -1e9};  // mm, mm, mm, deg, deg
  AxisValues soft_max{2700, 1450, 200, 120, 1e9};
  bool soft_limits = true;
  AxisValues rapid_per_min{20000, 20000, 5000, 7200, 7200};  // mm/min or deg/min per axis
  double max_feed_mm_per_min = 20000;       // feeds above are clamped, as a controller does
  double hold_decel_mm_per_s2 = 500;        // feed hold deceleration
  // Planner capacity in timed blocks (motion and dwell), the running one included. Zero-time
  // lines (comments, modal-only lines, M-codes) take none: grblHAL executes them in its parser
  // and never plans a block for them.
  std::size_t planner_blocks = 100;
  // G28's stored position in machine coordinates (grblHAL's G28 data, zero until G28.1 — which
  // the simulator does not implement — sets it).
  AxisValues g28_position{};
  ParseParams parse;
  // Fault injection: raise `alarm_code` when block number `alarm_at_seq` (1-based count of
  // accepted blocks) starts executing.
  std::optional<std::uint64_t> alarm_at_seq;
  GrblAlarm alarm_at_seq_code = GrblAlarm::hard_limit;
};

enum class MachineState { idle, run, hold_pending, hold, alarm };

// The spindle and coolant outputs as they are now (grblHAL's accessory state, the `A:` field).
struct Accessories {
  SpindleCommand spindle = SpindleCommand::off;
  bool flood = false, mist = false;
  bool operator==(const Accessories&) const = default;
};

// One block the machine executed (or started and was cut short by a reset or an alarm).
struct ExecutedBlock {
  std::uint64_t seq = 0;           // 1-based count of blocks accepted since start
  std::string line;                // the source text as received
  AxisValues start{}, end{};       // machine position when it started / ended
  bool jet = false;                // commanded jet state while it ran (after an M-code block)
  double t_start_s = 0, t_end_s = 0;
  bool completed = true;           // false: stopped part-way (end = where it stopped)
};
// The queue ran empty while a program was running (not held, not ended by M2/M30).
struct StarvationEvent {
  double t_s = 0;
  std::uint64_t after_seq = 0;
};
struct AlarmEvent {
  double t_s = 0;
  GrblAlarm code{};
  std::uint64_t seq = 0;  // block running or refused when it happened (0: none)
};
using MachineEvent = std::variant<ExecutedBlock, StarvationEvent, AlarmEvent>;

namespace detail {
// The planner's modal state (updated when a line is accepted, as Grbl's parser state is).
struct ModalState {
  bool relative = false;      // G91
  bool inches = false;        // G20
  bool inverse_time = false;  // G93
  MotionMode motion = MotionMode::rapid;  // Grbl powers up in G0
  std::optional<double> feed_mm_per_min;  // G94 feed; undefined after G93 → G94 (Grbl)
};

// One accepted line, planned: absolute start and target, duration, geometry.
struct PlannedBlock {
  std::uint64_t seq = 0;
  std::string line;
  std::optional<std::int64_t> line_number;
  double submit_s = 0;
  MotionMode kind = MotionMode::none;  // none: zero-time block (modal, comment, M-code)
  AxisValues start{}, target{};
  double duration_s = 0;        // > 0: a timed block, which occupies a planner slot
  double path_length = 0;       // mm (deg for a rotary-only move); hold deceleration runs on it
  double feed_mm_per_min = 0;   // effective feed reported while it runs
  double center_x = 0, center_y = 0, radius = 0, start_angle = 0, sweep = 0;  // arcs (rad)
  std::optional<AxisValues> via;  // G28's intermediate point: two straight legs, start → via → target
  std::optional<bool> jet_on;
  std::optional<SpindleCommand> spindle;
  std::optional<CoolantCommand> coolant;
  bool program_end = false;
};
}  // namespace detail

class Machine {
 public:
  explicit Machine(MachineConfig config);

  // Parse `line`, check it against the modal state and the soft limits, and queue it.
  // Blank / comment-only / modal-only lines are queued too (zero time, no capacity) so the
  // execution log repeats the program line for line, each line logged when it is reached;
  // `%` lines are not queued. A target outside the soft limits raises ALARM:2 (queue flushed,
  // motion stopped) and returns soft_limit. In alarm every line is refused with
  // system_gc_lock. A timed block that finds the planner full is refused with overflow and
  // changes nothing, so a caller may keep the line and try again (see has_room_for).
  GrblStatus submit_line(std::string_view line, double now_s);
  // Capacity is planner_blocks timed blocks (motion with a non-zero length and dwell with a
  // non-zero time); the running one keeps its slot until it finishes (Grbl).
  // has_room(): a timed block would fit. has_room_for(line): the line may be taken now — a
  // motion block needs a free slot (a zero-time line does not); a jet, spindle or coolant
  // M-code, M2/M30 and a dwell wait until the queue is empty (grblHAL's planner sync); a line
  // with an error or a soft-limit target is answered at once, as grblHAL checks them before
  // waiting. A dwell takes no planner slot: grblHAL dwells in mc_dwell, outside the planner.
  bool has_room() const;
  bool has_room_for(std::string_view line) const;
  std::size_t free_blocks() const;          // planner_blocks − queued_timed_blocks(): Grbl's Bf
  std::size_t queued_blocks() const;        // every queued line, zero-time ones and the running one included
  std::size_t queued_timed_blocks() const;  // the ones that occupy the planner (motion; not a dwell)
  std::size_t planner_blocks() const;       // the configured capacity ($I)
  // Simulated seconds of planned motion still to run: the running block's rest and every
  // queued block's duration (infinite in a hold: nothing runs down).
  double motion_ahead_s(double now_s) const;
  // Simulated seconds until at most `blocks` timed blocks are left (0 if there are no more now).
  double time_until_blocks_left(double now_s, std::size_t blocks) const;
  // The program is moving and only lines the host has not sent yet keep it going: a block runs,
  // no hold, no alarm, no dwell, and no sync (jet change, program end) is waiting for the drain.
  bool runs_on_host_lines() const;

  // Run the time model up to now_s: finish blocks, start the next ones, emit events.
  void advance(double now_s);

  // Real-time commands.
  void feed_hold(double now_s);     // decelerate (hold_pending), then hold
  void cycle_start(double now_s);   // resume from hold
  // Soft reset: stop at once, flush the queue, reset modal state to defaults. Returns true
  // when the machine was moving (the caller then raises ALARM:3 as Grbl does).
  bool reset(double now_s);
  void raise_alarm(GrblAlarm code, double now_s);  // stops motion, flushes, state alarm
  bool unlock();                                   // $X: leave alarm (false if e-stop held)
  void set_estop(bool pressed, double now_s);      // pressed → ALARM:10, unlock refused

  MachineState state() const;
  // Interpolated within the running block as of the last advance (call advance(now_s) first
  // for an exact answer; it does not start the next block itself).
  AxisValues position(double now_s) const;
  // Feed of the running move (0 when not moving): the effective path speed, so rapids and G93
  // moves report mm/min too (°/min for a rotary-only move).
  double feed_mm_per_min(double now_s) const;
  std::optional<std::int64_t> line_number() const; // N of the running block, if any
  std::uint64_t accepted_blocks() const;           // seq of the last accepted block
  std::uint64_t executed_blocks() const;           // blocks finished
  std::uint64_t starvation_count() const;
  bool jet_commanded() const;                      // CNC jet output (M-code) right now
  Accessories accessories() const;                 // spindle / coolant outputs right now
  std::uint64_t program_ends() const;              // M2/M30 executed since start
  std::optional<GrblAlarm> alarm() const;
  // A dwell is running (held or not). grblHAL reports Idle meanwhile: no motion is planned.
  bool dwelling() const;
  // Block `seq` is queued or running (false once it finished or a reset / alarm flushed it).
  bool pending(std::uint64_t seq) const;
  // The controller holds a line it takes as soon as the running dwell ends (grblHAL parses the
  // next line only when mc_dwell returns): the queue then runs dry on purpose, no starvation.
  void expect_line_after_dwell();

  // Events since the last call, in order (for the execution log and the protocols).
  std::vector<MachineEvent> take_events();

 private:
  // The running block's progress is a path fraction s ∈ [0, 1]: cruising at constant speed,
  // decelerating for a feed hold, or stopped (held).
  enum class Phase { cruise, decel, stopped };
  struct Running {
    detail::PlannedBlock block;
    double t_start_s = 0;
    Phase phase = Phase::cruise;
    double seg_t0_s = 0, seg_s0 = 0;          // the current phase began at (time, fraction)
    double decel_v = 0;                       // path units/s when the deceleration began
    double decel_tau_s = 0, decel_s_end = 0;  // deceleration length in time, fraction at its end
  };

  double fraction_at(const Running& r, double now_s) const;
  double phase_end_s(const Running& r) const;
  void start_next(double t_s);
  void finish_running(double t_s);
  void run_queue(double now_s);  // advance()'s work: blocks start and finish up to now_s
  void confirm_pending_stop(double now_s);
  void stop_running(double t_s);  // cut the running block short (reset, alarm)
  void alarm_stop(GrblAlarm code, double t_s, std::uint64_t seq);
  void reset_modal();
  // Parse and plan `line` against the current modal state without changing anything. nullopt
  // with `status` ok: a `%` line (nothing to queue).
  struct Planned {
    GrblStatus status = GrblStatus::ok;
    std::optional<detail::PlannedBlock> block;
    detail::ModalState modal;  // the modal state after the line
  };
  Planned plan_line(std::string_view line) const;

  MachineConfig config_;
  detail::ModalState modal_;
  AxisValues planned_pos_{};  // where the last queued block ends
  AxisValues pos_{};          // machine position when no block is running
  std::deque<detail::PlannedBlock> queue_;
  std::optional<Running> running_;
  double last_end_s_ = 0;     // the next block starts no earlier than this
  bool held_ = false;         // feed hold requested and not resumed
  std::optional<GrblAlarm> alarm_;
  bool estop_ = false;
  bool jet_ = false;
  Accessories accessories_;
  std::uint64_t program_ends_ = 0;
  bool program_running_ = false;
  bool moved_in_program_ = false;  // a timed block (motion, dwell) ran in this program
  bool starved_ = false;      // starvation already reported for this empty period
  // A jet change, program end or dwell waits for the queue to drain (has_room_for said no), or
  // a line waits behind a dwell: that empty queue is the program's own stop, not starvation.
  mutable bool draining_for_sync_ = false;
  std::optional<StarvationEvent> pending_stop_;  // the queue ran dry here; starvation unless a block comes at once
  double last_motion_end_s_ = -1;                // when the last timed block ended
  std::uint64_t accepted_ = 0, executed_ = 0, starvations_ = 0;
  std::vector<MachineEvent> events_;
};

}  // namespace lamina::sim
