#pragma once
// One sheet's program cut on the cell: bring the cell up (CellIo, optional), stream the program
// through a MachineLink, watch both, and on any fault stop safely — feed hold through the link,
// jet off through the PLC (the independent path), record where it stopped — and wait for the
// operator. It never resumes by itself: resume() is the operator's call, and restarts at the
// start of the contour that was being cut (resume_point.hpp).
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "lamina/drivers/cell_io.hpp"
#include "lamina/drivers/machine_link.hpp"
#include "lamina/drivers/resume_point.hpp"

namespace lamina::drivers {
namespace detail {
struct StarvationReading;
template <typename T>
class LatestRelay;
}

struct CutJobSettings {
  double stop_timeout_s = 5;        // feed hold → the machine reports Hold / Idle / Alarm
  double finish_timeout_s = 24 * 3600;  // everything accepted → the machine is Idle
  double safe_z_mm = 10;
  std::size_t planner_blocks = 0;   // 0: as the controller reported ([OPT:]); else configured
  // Wait for the controller to report Idle after the last line (needs status reports). A drip
  // feed has none: its cut is done, as far as the link can tell, when the last byte is out.
  bool wait_for_idle = true;
  // A feed hold that stands still turns the jet off through the PLC (hold_guard.hpp); resume
  // opens it and waits jet_restart_s before the motion continues; a hold longer than
  // hold_limit_s is a stop. Without a PLC a standing hold cannot turn the jet off: it is a stop.
  double hold_limit_s = 600;
  double jet_restart_s = 1.0;
  // Where the program's contours are, as the post made it (the plan's report); none: read from
  // its (CONTOUR n …) markers (a program from elsewhere, `lamina stream`).
  std::optional<ProgramMap> program_map = std::nullopt;
};

enum class CutState { ready, preparing, cutting, stopping, stopped, completed, failed };
const char* to_string(CutState state);

struct CutReport {
  CutState state = CutState::ready;
  std::optional<LinkError> reason;          // why it stopped or failed
  std::size_t lines_total = 0;
  std::size_t lines_accepted = 0;           // program lines acknowledged over all attempts
  std::size_t first_unfinished_line = 0;    // 0-based; == lines_total when all ran
  std::optional<ResumePlan> resume;         // set when stopped
  std::optional<ControllerStatus> last_status;
  double seconds = 0;
  std::size_t bytes_sent = 0;
  // The attempt streaming now (or last): what a supervisor persists so that after a crash the
  // CNC's executed-block count still places the stop. attempt_first_line is 0-based.
  std::optional<std::uint64_t> executed_base;  // the count when the attempt started
  std::size_t attempt_first_line = 0;
  std::size_t attempt_preamble_lines = 0;
};

class CutJob {
 public:
  // `cell` may be null (no PLC: dry runs, tests of the link alone).
  CutJob(MachineLink& link, CellIo* cell, std::vector<std::string> program, CutJobSettings settings = {});
  ~CutJob();  // unhooks its fault handler from the cell (the cell outlives jobs)
  CutJob(const CutJob&) = delete;
  CutJob& operator=(const CutJob&) = delete;

  // Blocking: the whole program, or until it stops. Then report().state is completed or stopped
  // (or failed when the cell could not be brought up).
  CutReport run();
  // Blocking: the operator's resume of a stopped job, from report().resume.
  CutReport resume();
  // Blocking: resume a cut another process (or run) left off — after a crash the supervisor
  // knows where from its records, not this object: from the start of the contour holding
  // first_unfinished_line (0-based). The cell is brought up first, as in run().
  CutReport resume_from(std::size_t first_unfinished_line);

  // From any thread (keyboard, daemon): feed hold / cycle start without stopping the job, and
  // abort (stops the job like a fault, reason cancelled). Both go over the line and through
  // the PLC's buttons (a drip feed has no hold on its line). While a program streams, the
  // resume after a hold that turned the jet off first opens it again (never blocks the caller).
  void hold();
  void continue_motion();
  void abort(std::string why);

  CutReport report() const;
  // Called (on a thread of the job's own; set before run) with each progress record.
  void on_progress(std::function<void(const CutReport&)> callback);
  // Called (on the hold watch's thread; set before run) when the machine is found standing in
  // a hold the job did not ask for, with the jet turned off: the PLC's or the controller's own
  // hold button (controller_held), or the machine ran dry mid-program (starved, and the job
  // held it). The job waits for continue_motion() as after hold().
  void on_hold(std::function<void(const LinkError&)> callback);

 private:
  CutReport stream_from(std::size_t from, std::vector<std::string> preamble);  // with the hold watch
  CutReport stream_span(std::size_t from, std::vector<std::string> preamble);
  LinkCallbacks span_callbacks(std::shared_ptr<detail::LatestRelay<CutReport>> relay);
  std::optional<LinkError> wait_until_run_out();
  bool refuse_unsendable();
  // Blocks the CNC has finished, from the link's status or the PLC's (nullopt: neither says),
  // after one more report came in.
  std::optional<std::uint64_t> executed_blocks();
  void stop_safely(LinkError why);
  std::optional<LinkError> jet_off_without_plc(bool axes_still);
  std::function<void(const CellFaultReport&)> fault_handler();
  void set_state(CutState state);
  // The hold watch: a thread beside stream_from that applies the hold rule to the state the
  // controller (or the PLC) reports, and carries out the operator's resume.
  void start_hold_watch();
  void stop_hold_watch();
  void watch_holds();
  ControllerState observed_state() const;
  std::optional<detail::StarvationReading> starvation_reading(std::chrono::steady_clock::time_point t0) const;
  std::optional<LinkError> hold_stop() const;

  MachineLink& link_;
  CellIo* cell_;
  std::vector<std::string> program_;
  ProgramMap map_;
  CutJobSettings settings_;
  mutable std::mutex mutex_;
  CutReport report_;
  std::function<void(const CutReport&)> progress_;
  std::function<void(const LinkError&)> on_hold_;
  std::atomic<bool> stopping_{false};
  std::optional<LinkError> stop_reason_;
  std::size_t span_first_ = 0;
  // Acknowledged lines and planner occupancy at the last status report (for the resume point).
  std::size_t accepted_at_status_ = 0;
  std::optional<std::size_t> queued_at_status_;
  // The CNC's executed-block count before this attempt's first line, and the preamble length:
  // program line from + k has run once the count passes base + preamble + k.
  std::optional<std::uint64_t> executed_base_;
  std::size_t preamble_lines_ = 0;
  std::thread hold_thread_;
  mutable std::mutex hold_mutex_;  // guards the four below
  std::condition_variable hold_wake_;
  bool hold_watching_ = false;
  bool resume_requested_ = false;
  std::optional<LinkError> hold_stop_;  // the hold rule stopped the job (read by stream_from)
};

}  // namespace lamina::drivers
