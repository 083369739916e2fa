#include "lamina/drivers/cut_job.hpp"

#include <chrono>
#include <memory>
#include <thread>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "latest_relay.hpp"

namespace lamina::drivers {
namespace {

using Clock = std::chrono::steady_clock;

bool stopped_moving(ControllerState s) {
  return s == ControllerState::hold || s == ControllerState::idle || s == ControllerState::alarm ||
         s == ControllerState::door;
}

}  // namespace

const char* to_string(CutState state) {
  switch (state) {
    case CutState::ready: return "ready";
    case CutState::preparing: return "preparing";
    case CutState::cutting: return "cutting";
    case CutState::stopping: return "stopping";
    case CutState::stopped: return "stopped";
    case CutState::completed: return "completed";
    case CutState::failed: return "failed";
  }
  return "?";
}

CutJob::CutJob(MachineLink& link, CellIo* cell, std::vector<std::string> program, CutJobSettings settings)
    : link_(link), cell_(cell), program_(std::move(program)), settings_(std::move(settings)) {
  report_.lines_total = program_.size();
  map_ = settings_.program_map ? *settings_.program_map : program_map_from_markers(program_);
}

CutJob::~CutJob() {
  stop_hold_watch();
  if (cell_) cell_->on_fault(nullptr);
}

CutReport CutJob::report() const {
  std::lock_guard lock(mutex_);
  return report_;
}

void CutJob::on_progress(std::function<void(const CutReport&)> callback) { progress_ = std::move(callback); }

void CutJob::set_state(CutState state) {
  std::lock_guard lock(mutex_);
  report_.state = state;
}


void CutJob::abort(std::string why) {
  // Jet first: the PLC path does not wait for anything queued on the serial line.
  if (cell_) {
    cell_->jet_off();
    cell_->feed_hold();
  }
  link_.request(RealtimeCommand::feed_hold);
  link_.stop(LinkError{LinkErrorCode::cancelled, std::move(why)});
}

std::function<void(const CellFaultReport&)> CutJob::fault_handler() {
  return [this](const CellFaultReport& fault) {
    // The PLC already dropped the jet; hold the motion and stop the stream.
    cell_->jet_off();
    cell_->feed_hold();
    link_.request(RealtimeCommand::feed_hold);
    link_.stop(LinkError{LinkErrorCode::interlock, fault.message});
  };
}

// A line the link must not send is found before the pump starts or a byte goes out.
bool CutJob::refuse_unsendable() {
  auto bad = link_.check_lines(program_, 0);
  if (!bad) return false;
  std::lock_guard lock(mutex_);
  report_.state = CutState::failed;
  report_.reason = std::move(bad);
  return true;
}

CutReport CutJob::run() {
  if (refuse_unsendable()) return report();
  if (cell_) {
    set_state(CutState::preparing);
    cell_->on_fault(fault_handler());
    if (auto ready = cell_->prepare_cut(); !ready) {
      std::lock_guard lock(mutex_);
      report_.state = CutState::failed;
      report_.reason = ready.error();
      return report_;
    }
  }
  return stream_from(0, {});
}

CutReport CutJob::resume_from(std::size_t first_unfinished_line) {
  if (refuse_unsendable()) return report();
  if (cell_) cell_->on_fault(fault_handler());
  {
    std::lock_guard lock(mutex_);
    report_.first_unfinished_line = std::min(first_unfinished_line, program_.size());
    auto plan = plan_resume(program_, map_, report_.first_unfinished_line, settings_.safe_z_mm);
    if (!plan) {
      report_.state = CutState::failed;
      report_.reason = plan.error();
      return report_;
    }
    report_.resume = *plan;
    report_.state = CutState::stopped;
  }
  return resume();
}

CutReport CutJob::resume() {
  std::optional<ResumePlan> plan;
  {
    std::lock_guard lock(mutex_);
    if (report_.state != CutState::stopped || !report_.resume) return report_;
    plan = report_.resume;
  }
  if (!link_.can_reset() && cell_) {
    // The queue a held drip feed still holds must go before the program restarts: the PLC's
    // reset button, then the CNC reads idle (recover() below waits for the line's release).
    if (auto reset = cell_->reset_cnc(); !reset) {
      std::lock_guard lock(mutex_);
      report_.reason = reset.error();
      return report_;  // still stopped
    }
  }
  if (auto error = link_.recover(settings_.stop_timeout_s)) {
    std::lock_guard lock(mutex_);
    report_.reason = *error;
    return report_;  // still stopped: the operator sees why the controller did not recover
  }
  if (cell_) {
    if (auto ready = cell_->prepare_cut(); !ready) {
      std::lock_guard lock(mutex_);
      report_.reason = ready.error();
      return report_;
    }
  }
  spdlog::info("cut: resuming at line {} (contour {})", plan->restart_index + 1, plan->contour);
  return stream_from(plan->restart_index, plan->preamble);
}

std::optional<std::uint64_t> CutJob::executed_blocks() {
  // Let one more report come in (the link's status period, the PLC's poll) so the count is
  // not older than the moment we care about.
  const std::size_t before = link_.progress().statuses_received;
  const auto deadline = Clock::now() + std::chrono::milliseconds(600);
  while (Clock::now() < deadline && link_.progress().statuses_received < before + 2 && !cell_)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  if (cell_) std::this_thread::sleep_for(std::chrono::milliseconds(150));
  if (const auto p = link_.progress(); p.last_status && p.last_status->executed_blocks) return p.last_status->executed_blocks;
  if (cell_) return cell_->status().cnc_executed_blocks;
  return std::nullopt;
}

CutReport CutJob::stream_from(std::size_t from, std::vector<std::string> preamble) {
  start_hold_watch();
  CutReport r = stream_span(from, std::move(preamble));
  stop_hold_watch();
  return r;
}

// What the link tells this job while a span streams: the report's status and resume data, and
// the progress records, handed to `relay` (null: nobody listens).
LinkCallbacks CutJob::span_callbacks(std::shared_ptr<detail::LatestRelay<CutReport>> relay) {
  LinkCallbacks callbacks;
  callbacks.on_status = [this](const ControllerStatus& status) {
    const LinkProgress p = link_.progress();
    std::lock_guard lock(mutex_);
    report_.last_status = status;
    // An alarm flushes the controller's queue: its Bf then says nothing of what ran.
    if (status.state == ControllerState::alarm || stopping_) return;
    const auto capacity = settings_.planner_blocks ? std::optional<int>(static_cast<int>(settings_.planner_blocks))
                                                   : p.planner_blocks;
    if (capacity && status.planner_blocks_free) {
      accepted_at_status_ = span_first_ + p.lines_accepted;
      queued_at_status_ = static_cast<std::size_t>(std::max(0, *capacity - *status.planner_blocks_free));
    }
  };
  callbacks.on_progress = [this, relay](const LinkProgress& p) {
    {
      std::lock_guard lock(mutex_);
      report_.lines_accepted = span_first_ + p.lines_accepted;
      report_.bytes_sent = p.bytes_sent;
    }
    if (relay) relay->post(report());
  };
  return callbacks;
}

CutReport CutJob::stream_span(std::size_t from, std::vector<std::string> preamble) {
  stopping_ = false;
  set_state(CutState::cutting);
  const auto started = Clock::now();
  // The machine stands still here (fresh, or recovered): its count is this attempt's base.
  executed_base_ = executed_blocks();
  preamble_lines_ = preamble.size();
  {
    std::lock_guard lock(mutex_);
    report_.executed_base = executed_base_;
    report_.attempt_first_line = from;
    report_.attempt_preamble_lines = preamble_lines_;
  }
  if (!preamble.empty()) {
    link_.start(LineSpan{std::move(preamble), 0}, {});
    const auto outcome = link_.wait(settings_.stop_timeout_s * 4);
    if (!outcome || !outcome->completed) {
      stop_safely(outcome && outcome->error ? *outcome->error
                                            : LinkError{LinkErrorCode::timeout, "the resume preamble was not accepted"});
      return report();
    }
  }
  span_first_ = from;
  {
    std::lock_guard lock(mutex_);
    accepted_at_status_ = from;
    queued_at_status_.reset();
  }
  // Progress records leave the link's thread (latest_relay.hpp). The relay is closed, its last
  // callback done, before this returns: the owner records the outcome after, never before it.
  const auto relay = progress_ ? std::make_shared<detail::LatestRelay<CutReport>>(progress_) : nullptr;
  struct CloseRelay {
    std::shared_ptr<detail::LatestRelay<CutReport>> relay;
    ~CloseRelay() {
      if (relay) relay->close();
    }
  } close_relay{relay};
  const LinkCallbacks callbacks = span_callbacks(relay);
  std::vector<std::string> lines(program_.begin() + static_cast<std::ptrdiff_t>(from), program_.end());
  link_.start(LineSpan{std::move(lines), from}, callbacks);
  auto outcome = link_.wait(settings_.finish_timeout_s);
  if (!outcome) {
    link_.stop(LinkError{LinkErrorCode::timeout, "the program did not finish in time"});
    outcome = link_.wait(settings_.stop_timeout_s);
  }
  if (outcome && outcome->completed) {
    if (auto why = wait_until_run_out()) {
      stop_safely(*why);
      return report();
    }
    if (cell_) (void)cell_->finish_cut();
    std::lock_guard lock(mutex_);
    report_.state = CutState::completed;
    report_.lines_accepted = program_.size();
    report_.first_unfinished_line = program_.size();
    report_.resume.reset();
    report_.reason.reset();
    report_.seconds += std::chrono::duration<double>(Clock::now() - started).count();
    return report_;
  }
  stop_safely(outcome && outcome->error ? *outcome->error : LinkError{LinkErrorCode::timeout, "no outcome"});
  std::lock_guard lock(mutex_);
  report_.seconds += std::chrono::duration<double>(Clock::now() - started).count();
  return report_;
}

// Everything is in the controller; the cut is done when it has run it all (Idle, twice, in
// reports asked for after the last line went out). nullopt when it has, else why it stops.
std::optional<LinkError> CutJob::wait_until_run_out() {
  if (!settings_.wait_for_idle) return std::nullopt;  // a drip feed reports nothing: out is done
  int idle_reports = 0;
  std::size_t last_seen = link_.progress().statuses_received;
  const auto deadline = Clock::now() + std::chrono::duration<double>(settings_.finish_timeout_s);
  while (Clock::now() < deadline && !stopping_ && !hold_stop()) {
    const LinkProgress p = link_.progress();
    if (p.statuses_received != last_seen && p.last_status) {
      last_seen = p.statuses_received;
      if (p.last_status->state == ControllerState::alarm)
        return LinkError{LinkErrorCode::controller_alarm, "the controller alarmed while finishing the program"};
      idle_reports = p.last_status->state == ControllerState::idle ? idle_reports + 1 : 0;
      if (idle_reports >= 2) return std::nullopt;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return stop_reason_.value_or(
      hold_stop().value_or(LinkError{LinkErrorCode::timeout, "the machine did not finish the program"}));
}

// With no PLC the controller's own M-code is the only jet output, and a feed hold keeps it on:
// the soft reset turns it off (grbl's mc_reset stops spindle and coolant). Done once the axes
// stand still, so the reset costs no position; a controller that never reported still is reset
// anyway — a jet on a standing machine drills the part, a lost position only needs homing.
std::optional<LinkError> CutJob::jet_off_without_plc(bool axes_still) {
  if (cell_ || !link_.can_reset()) return std::nullopt;
  if (!axes_still) spdlog::warn("cut: the machine did not report standing still; resetting it anyway (jet off)");
  if (auto error = link_.reset(settings_.stop_timeout_s))
    return LinkError{error->code, "the soft reset that turns the jet off went unanswered (" + error->message + ")"};
  return std::nullopt;
}

void CutJob::stop_safely(LinkError why) {
  stopping_ = true;
  set_state(CutState::stopping);
  spdlog::warn("cut: stopping: {}", why.message);
  if (cell_) {
    cell_->jet_off();
    cell_->feed_hold();  // a drip feed has no real-time hold on its line
  }
  link_.request(RealtimeCommand::feed_hold);
  // Wait for a report asked after the hold that says the axes stand still.
  const std::size_t before = link_.progress().statuses_received;
  const auto deadline = Clock::now() + std::chrono::duration<double>(settings_.stop_timeout_s);
  std::optional<ControllerStatus> still;
  while (Clock::now() < deadline) {
    const LinkProgress p = link_.progress();
    if (p.statuses_received > before + 1 && p.last_status && stopped_moving(p.last_status->state)) {
      still = p.last_status;
      break;
    }
    // A drip feed reports nothing on its line: the PLC's reading of the CNC's state lamps.
    if (cell_ && p.statuses_received == 0 && stopped_moving(cell_->status().cnc_state)) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  const LinkProgress p = link_.progress();
  // (plain value + flag: g++ 12 warns falsely about an optional here)
  std::uint64_t executed_now = 0;
  bool have_executed = false;
  if (executed_base_) {
    if (const auto e = executed_blocks()) {
      executed_now = *e;
      have_executed = true;
    }
  }
  const std::optional<LinkError> reset_failed = jet_off_without_plc(still.has_value());
  std::lock_guard lock(mutex_);
  std::size_t accepted = accepted_at_status_;
  std::size_t queued = queued_at_status_.value_or(program_.size());  // unknown: assume all may be queued
  const auto capacity = settings_.planner_blocks ? std::optional<int>(static_cast<int>(settings_.planner_blocks))
                                                 : p.planner_blocks;
  if (still && still->state == ControllerState::hold && capacity && still->planner_blocks_free) {
    // Held with its queue intact: what is queued is exactly what has not run.
    accepted = span_first_ + p.lines_accepted;
    queued = static_cast<std::size_t>(std::max(0, *capacity - *still->planner_blocks_free));
  }
  report_.first_unfinished_line = first_unfinished_line(program_, accepted, queued);
  const bool held_with_queue = still && still->state == ControllerState::hold && capacity && still->planner_blocks_free;
  if (!held_with_queue && executed_base_) {
    // No queue to read (a drip feed, the mailbox, an alarm that flushed it): the CNC's own
    // count of finished blocks says which line it was on.
    if (have_executed && executed_now >= *executed_base_ + preamble_lines_) {
      const std::size_t ran = static_cast<std::size_t>(executed_now - *executed_base_ - preamble_lines_);
      report_.first_unfinished_line = std::min(program_.size(), span_first_ + ran);
    }
  }
  report_.reason = why;
  // The controller often speaks first (ALARM, NAK) about what the PLC knows the cause of.
  if (cell_ && why.code != LinkErrorCode::interlock)
    if (const auto cell_fault = cell_->fault()) report_.reason->message += " (cell: " + cell_fault->message + ")";
  if (reset_failed) report_.reason->message += "; " + reset_failed->message;
  report_.last_status = still ? still : report_.last_status;
  if (auto plan = plan_resume(program_, map_, report_.first_unfinished_line, settings_.safe_z_mm)) {
    report_.resume = *plan;
  } else {
    report_.resume.reset();
    report_.reason->message += "; " + plan.error().message;
  }
  report_.state = CutState::stopped;
  stop_reason_ = why;
}

}  // namespace lamina::drivers
