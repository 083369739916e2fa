// CutJob's hold watch (issue 16, item 1): the rule is hold_guard.hpp; this file carries out
// its actions on the cell and the link, on a thread of its own beside the stream, so neither
// the operator's resume call nor the link's status callback ever waits on the PLC.
#include <chrono>

#include <spdlog/spdlog.h>

#include "hold_guard.hpp"
#include "latest_relay.hpp"
#include "lamina/drivers/cut_job.hpp"
#include "starvation_watch.hpp"

namespace lamina::drivers {
namespace {
using Clock = std::chrono::steady_clock;
constexpr auto kWatchPeriod = std::chrono::milliseconds(10);
}  // namespace

void CutJob::hold() {
  link_.request(RealtimeCommand::feed_hold);
  if (cell_) cell_->feed_hold();  // the only hold a drip feed has; a second one for grbl
}

void CutJob::continue_motion() {
  {
    std::lock_guard lock(hold_mutex_);
    if (hold_watching_) {
      resume_requested_ = true;
      hold_wake_.notify_all();
      return;
    }
  }
  link_.request(RealtimeCommand::resume);
  if (cell_) cell_->cycle_start();
}

void CutJob::start_hold_watch() {
  stop_hold_watch();
  {
    std::lock_guard lock(hold_mutex_);
    hold_watching_ = true;
    resume_requested_ = false;
    hold_stop_.reset();
  }
  hold_thread_ = std::thread([this] { watch_holds(); });
}

void CutJob::stop_hold_watch() {
  {
    std::lock_guard lock(hold_mutex_);
    hold_watching_ = false;
  }
  hold_wake_.notify_all();
  if (hold_thread_.joinable()) hold_thread_.join();
}

std::optional<LinkError> CutJob::hold_stop() const {
  std::lock_guard lock(hold_mutex_);
  return hold_stop_;
}

// The link's own reports where it has them (grbl: `Hold:0` vs `Hold:1`), else the PLC's
// reading of the CNC's state lamps (a drip feed, the mailbox).
ControllerState CutJob::observed_state() const {
  const LinkProgress p = link_.progress();
  if (p.statuses_received > 0 && p.last_status) return p.last_status->state;
  if (cell_) return cell_->status().cnc_state;
  return ControllerState::unknown;
}

void CutJob::on_hold(std::function<void(const LinkError&)> callback) { on_hold_ = std::move(callback); }

// What the PLC shows of the machine for the starvation rule; nullopt while there is nothing to
// judge (no PLC, no count, the resume's preamble, the span not loaded yet).
std::optional<detail::StarvationReading> CutJob::starvation_reading(Clock::time_point t0) const {
  if (!cell_) return std::nullopt;  // no PLC, no water: the valve's consent is the PLC's
  const CellStatus c = cell_->status();
  if (!c.read_at || !c.cnc_executed_blocks) return std::nullopt;
  std::size_t from = 0, preamble = 0;
  std::optional<std::uint64_t> base;
  {
    std::lock_guard lock(mutex_);
    from = report_.attempt_first_line;
    preamble = report_.attempt_preamble_lines;
    base = report_.executed_base;
  }
  const LinkProgress p = link_.progress();
  if (!base || p.lines_total != program_.size() - from) return std::nullopt;
  detail::StarvationReading r;
  r.cnc_state = c.cnc_state;
  r.water_flowing = c.jet_is_on && c.cnc_jet_request;
  if (*c.cnc_executed_blocks >= *base + preamble)
    r.standing_at = from + static_cast<std::size_t>(*c.cnc_executed_blocks - *base - preamble);
  r.lines_sent_end = from + p.lines_sent;
  r.read_at_s = std::chrono::duration<double>(*c.read_at - t0).count();
  return r;
}

void CutJob::watch_holds() {
  detail::HoldGuard guard({.hold_limit_s = settings_.hold_limit_s, .jet_restart_s = settings_.jet_restart_s});
  detail::StarvationWatch starvation(program_);
  const auto t0 = Clock::now();
  // The owner records the hold (a synced write): never on this thread, which must go on watching.
  detail::LatestRelay<LinkError> announcements([this](const LinkError& why) { if (on_hold_) on_hold_(why); });
  const auto announce = [&](const LinkError& why) { announcements.post(why); };
  const auto stop_job = [&](LinkError why) {
    spdlog::warn("cut: {}", why.message);
    {
      std::lock_guard lock(hold_mutex_);
      hold_stop_ = why;
    }
    link_.stop(std::move(why));
  };
  const auto act = [&](detail::HoldAction action) {
    switch (action) {
      case detail::HoldAction::none: return;
      case detail::HoldAction::jet_off:
        if (!cell_)
          return stop_job({LinkErrorCode::held_too_long,
                           "the machine stands in a feed hold and there is no PLC to turn the jet off: stopped"});
        spdlog::info("cut: the machine stands in a feed hold: jet and abrasive off");
        cell_->pause_jet();
        return announce({LinkErrorCode::controller_held, "the machine stands in a feed hold: jet and abrasive off"});
      case detail::HoldAction::jet_on:
        if (!cell_) return;
        spdlog::info("cut: resuming the hold: jet and abrasive on, motion in {:.1f} s", settings_.jet_restart_s);
        if (auto r = cell_->restore_jet(); !r) return stop_job(r.error());
        guard.on_jet_opened(std::chrono::duration<double>(Clock::now() - t0).count());
        return;
      case detail::HoldAction::cycle_start:
        link_.request(RealtimeCommand::resume);
        if (cell_) cell_->cycle_start();
        return;
      case detail::HoldAction::stop: return stop_job(*guard.stop_reason());
      case detail::HoldAction::starved_hold: return;  // carried out below, with its reason
    }
  };
  // The starvation was seen by the PLC; the link's last report may be older than it and still
  // say Run. Its state counts again from the second report after the hold was asked for.
  std::optional<std::size_t> stale_reports_until;
  const auto check_starvation = [&](double now_s) {
    const auto reading = starvation_reading(t0);
    const auto dry = reading ? starvation.on_reading(*reading) : std::nullopt;
    if (!dry || guard.stop_reason() || hold_stop()) return;
    if (!dry->host_behind) {
      if (cell_) cell_->jet_off();  // the independent path first: the stop goes through the link
      return stop_job(dry->why);
    }
    if (guard.on_starved(now_s) != detail::HoldAction::starved_hold) return;
    spdlog::warn("cut: {}", dry->why.message);
    stale_reports_until = link_.progress().statuses_received + 1;
    hold();  // the motion first: lines on their way must not run dry
    if (cell_) cell_->pause_jet();
    announce(dry->why);
  };
  const auto fresh_state = [&]() -> std::optional<ControllerState> {
    if (stale_reports_until && link_.progress().statuses_received <= *stale_reports_until) return std::nullopt;
    stale_reports_until.reset();
    return observed_state();
  };
  std::unique_lock lock(hold_mutex_);
  while (hold_watching_) {
    hold_wake_.wait_for(lock, kWatchPeriod, [this] { return !hold_watching_ || resume_requested_; });
    if (!hold_watching_) break;
    const bool resume = std::exchange(resume_requested_, false);
    lock.unlock();
    const double now_s = std::chrono::duration<double>(Clock::now() - t0).count();
    // Before our first line a held controller is the streamer's to report (controller_held).
    if (!stopping_ && link_.progress().lines_sent > 0) {
      if (resume) act(guard.on_resume_request(now_s));
      if (const auto state = fresh_state()) act(guard.on_state(*state, now_s));
      check_starvation(now_s);
    } else if (resume && !stopping_) {
      link_.request(RealtimeCommand::resume);  // nothing of ours is in the controller yet
    }
    lock.lock();
  }
}

}  // namespace lamina::drivers
