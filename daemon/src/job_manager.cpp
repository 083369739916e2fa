// JobManager: the RPC-facing half (submit, list, cancel, confirm, resume, machine requests) and
// planning. The cutting thread is in job_cutting.cpp.
#include "job_manager.hpp"

#include "client_files.hpp"

#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <random>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "plan_process.hpp"
#include "plan_settings.hpp"

namespace lamina::daemon {
namespace fs = std::filesystem;

namespace {

std::string new_job_id() {
  static std::mt19937 rng{std::random_device{}()};
  return fmt::format("j-{}-{:04x}", now_unix_ms(), rng() & 0xFFFF);
}


std::shared_ptr<spdlog::logger> jobs_log() {
  static auto logger = [] {
    auto l = spdlog::get("jobs");
    return l ? l : spdlog::default_logger()->clone("jobs");
  }();
  return logger;
}

// Which transitions the state machine allows (docs/api.md "Job states").
bool allowed(JobState from, JobState to) {
  using S = JobState;
  if (to == S::cancelled) return !is_terminal(from);
  if (to == S::interrupted) return from == S::cutting || from == S::paused || from == S::sheet_done || from == S::waiting_sheet;
  switch (from) {
    case S::queued: return to == S::planning;
    case S::planning: return to == S::planned || to == S::failed || to == S::queued;
    case S::planned: return to == S::waiting_sheet;
    case S::waiting_sheet: return to == S::cutting;
    case S::cutting: return to == S::paused || to == S::sheet_done || to == S::completed;
    case S::paused: return to == S::cutting || to == S::paused || to == S::sheet_done || to == S::completed;
    case S::sheet_done: return to == S::waiting_sheet || to == S::completed;
    case S::interrupted: return to == S::cutting;
    default: return false;
  }
}

std::string model_name(const std::string& path) { return fs::path(path).filename().string(); }

}  // namespace

JobManager::JobManager(const DaemonConfig& config, JobStore& store, MachineSession& machine, Notifier notify)
    : config_(config), store_(store), machine_(machine), notify_(std::move(notify)) {}

JobManager::~JobManager() { shutdown("daemon stopping"); }

std::expected<void, JobError> JobManager::start() {
  auto all = store_.list_jobs();
  if (!all) return std::unexpected(job_error(JobErrorKind::storage, all.error().message));
  std::lock_guard lock(mutex_);
  for (JobRecord& job : *all) {
    if (job.state == JobState::queued) plan_queue_.push_back(job.id);
    // The sheet on the table belongs to the job that was waiting for it or was cutting it when
    // the daemon stopped: that job keeps the machine until it is resumed or cancelled.
    if (job.state == JobState::waiting_sheet || job.state == JobState::interrupted) machine_job_ = job.id;
    jobs_[job.id] = std::move(job);
  }
  const int workers = std::max(1, config_.planner.workers);
  for (int i = 0; i < workers; ++i) planners_.emplace_back([this] { planner_loop(); });
  assign_machine();
  return {};
}

void JobManager::shutdown(const std::string& why) {
  std::shared_ptr<drivers::CutJob> cut;
  {
    std::lock_guard lock(mutex_);
    if (stopping_ && planners_.empty() && !cutter_.joinable()) return;
    stopping_ = true;
    for (auto& [id, flag] : plan_cancel_) flag->store(true);
    if (cutting_) cut = cut_;
  }
  plan_wake_.notify_all();
  if (cut) cut->abort(why);  // the cutter thread marks its job interrupted (stopping_)
  for (auto& t : planners_)
    if (t.joinable()) t.join();
  planners_.clear();
  if (cutter_.joinable()) cutter_.join();
  std::lock_guard lock(mutex_);
  // A job that owned the machine but was not streaming (held, waiting) is interrupted too:
  // after a restart nobody may assume its sheet is still where it was.
  if (JobRecord* job = find(machine_job_); job && (job->state == JobState::paused || job->state == JobState::sheet_done))
    (void)set_state(*job, JobState::interrupted, why);
}

// ---------------------------------------------------------------------------- state machine

// Disk first, memory after: a state the database did not take is not taken at all (the job is
// read back as the database has it), so what clients are told never runs ahead of a restart.
std::expected<void, JobError> JobManager::set_state(JobRecord& job, JobState to, const std::string& why) {
  if (auto refused = store_refusal()) {
    reload(job);
    return std::unexpected(*refused);
  }
  if (!allowed(job.state, to))
    return std::unexpected(job_error(JobErrorKind::wrong_state, fmt::format("job {} is {}: it cannot become {}", job.id,
                                                                      to_string(job.state), to_string(to))));
  const JobState from = job.state;
  JobRecord next = job;
  next.state = to;
  next.updated_unix_ms = now_unix_ms();
  if (!why.empty() || to == JobState::cutting || to == JobState::completed) next.error = why;
  if (auto r = store_.update_job(next); !r) {
    store_failed(r.error().message);
    reload(job);
    return std::unexpected(*store_refusal());
  }
  job = std::move(next);
  event(job, "state", {{"from", to_string(from)}, {"to", to_string(to)}, {"reason", why}});
  jobs_log()->info("job {}: {} → {}{}", job.id, to_string(from), to_string(to), why.empty() ? "" : " (" + why + ")");
  announce(job);
  return {};
}

// Before the state change it causes, so the log reads cause then effect.
void JobManager::action(const JobRecord& job, const std::string& what, const Actor& by, nlohmann::json data) {
  data["action"] = what;
  data["by"] = by.user;
  data["role"] = role_name(by.role);
  event(job, "action", std::move(data));
}

void JobManager::event(const JobRecord& job, const std::string& kind, nlohmann::json data) {
  if (auto r = store_.add_event(JobEvent{job.id, now_unix_ms(), kind, std::move(data)}); !r) store_failed(r.error().message);
}

// Issue 16, item 6: with the state directory full the cut went on, progress was only logged,
// and a restart then re-cut finished contours. A write that fails stops the cut (jet off, feed
// hold, its resume point kept by the CNC's count) and every request that would write is
// refused with -32014 until laminad is restarted with room on the disk. Hold and abort still work.
void JobManager::store_failed(const std::string& message) {
  if (store_fault_) return;
  store_fault_ = message;
  jobs_log()->critical("the job store cannot be written: {}. The cut is stopped; free the disk and restart laminad", message);
  if (cutting_ && cut_) cut_->abort(fmt::format("the job store cannot be written ({})", message));
  if (notify_) notify_("notify_machine_status", {{"store", {{"ok", false}, {"error", message}}}});
}

std::optional<JobError> JobManager::store_refusal() const {
  if (!store_fault_) return std::nullopt;
  return job_error(JobErrorKind::storage,
               fmt::format("the job store cannot be written ({}): nothing was changed; free space under {} and "
                           "restart laminad",
                           *store_fault_, config_.state_dir.string()));
}

void JobManager::reload(JobRecord& job) {
  auto disk = store_.get_job(job.id);
  if (disk && *disk) job = std::move(**disk);
}

void JobManager::announce(const JobRecord& job) {
  if (notify_) notify_("notify_job_progress", to_json(job));
}

JobRecord* JobManager::find(const std::string& id) {
  auto it = jobs_.find(id);
  return it == jobs_.end() ? nullptr : &it->second;
}
const JobRecord* JobManager::find(const std::string& id) const {
  auto it = jobs_.find(id);
  return it == jobs_.end() ? nullptr : &it->second;
}

void JobManager::assign_machine() {
  if (!machine_job_.empty() || stopping_) return;
  JobRecord* oldest = nullptr;
  for (auto& [id, job] : jobs_)
    if (job.state == JobState::planned && (!oldest || job.created_unix_ms < oldest->created_unix_ms)) oldest = &job;
  if (!oldest) return;
  machine_job_ = oldest->id;
  oldest->current_sheet = 0;
  for (const SheetRecord& s : oldest->sheets)
    if (s.state != SheetState::done) {
      oldest->current_sheet = s.index;
      break;
    }
  (void)set_state(*oldest, JobState::waiting_sheet,
                  fmt::format("load sheet {} and confirm it", oldest->current_sheet));
}

// ---------------------------------------------------------------------------- requests

// The job's inputs go into its folder before it exists for anyone: an upload moves there, a
// file named by path is checked against the roots and copied (client_files.hpp), and so is a
// stock file. jobs/<id>/input/, apart from what the planner writes (a model named stack.stl
// would otherwise be overwritten by the plan's own).
std::expected<void, JobError> JobManager::stage_inputs(JobRecord& job, const SubmitRequest& r) const {
  const fs::path input = fs::path(job.artefact_dir) / "input";
  std::vector<fs::path> roots(config_.jobs.roots.begin(), config_.jobs.roots.end());
  if (r.move_into_job) {
    std::error_code ec;
    fs::create_directories(input, ec);
    const std::string stored = fs::path(r.model_path).filename().string();  // "<upload id>-<name>"
    const fs::path target = input / stored.substr(stored.find('-') + 1);
    fs::rename(r.model_path, target, ec);
    if (ec) return std::unexpected(job_error(JobErrorKind::storage, fmt::format("{}: {}", target.string(), ec.message())));
    job.model_path = target.string();
  } else {
    auto copy = import_client_file(r.model_path, "model", {roots, config_.jobs.max_model_bytes}, input);
    if (!copy) return std::unexpected(copy.error());
    job.model_path = copy->string();
  }
  if (job.plan_settings.contains("stock_file")) {
    auto copy = import_client_file(job.plan_settings["stock_file"].get<std::string>(), "settings.stock_file",
                                   {roots, config_.jobs.max_stock_file_bytes}, input / "stock");
    if (!copy) return std::unexpected(copy.error());
    job.plan_settings["stock_file"] = copy->string();
  }
  return {};
}

std::expected<JobRecord, JobError> JobManager::submit(SubmitRequest r) {
  std::error_code ec;
  auto fail = [&](JobError e, const JobRecord* job) -> std::expected<JobRecord, JobError> {
    if (r.move_into_job) fs::remove(r.model_path, ec);  // a refused upload is not kept
    if (job) fs::remove_all(job->artefact_dir, ec);
    return std::unexpected(std::move(e));
  };
  auto args = plan_args_from_settings(r.settings);
  if (!args) return fail(job_error(JobErrorKind::bad_request, args.error()), nullptr);
  {
    std::lock_guard lock(mutex_);
    if (auto refused = store_refusal()) return fail(*refused, nullptr);
  }

  JobRecord job;
  job.id = new_job_id();
  job.name = r.name.empty() ? model_name(r.model_path) : r.name;
  if (r.move_into_job && r.name.empty()) {
    const std::string stored = model_name(r.model_path);
    job.name = stored.substr(stored.find('-') + 1);
  }
  job.plan_settings = r.settings.is_null() ? nlohmann::json::object() : r.settings;
  job.artefact_dir = (config_.state_dir / "jobs" / job.id).string();
  job.created_unix_ms = job.updated_unix_ms = now_unix_ms();
  // File work outside the lock: a large model's copy must not hold up the cut's bookkeeping.
  if (auto staged = stage_inputs(job, r); !staged) return fail(staged.error(), &job);

  std::lock_guard lock(mutex_);
  if (stopping_) return fail(job_error(JobErrorKind::shutting_down, "the daemon is stopping"), &job);
  if (auto s = store_.insert_job(job); !s) {
    store_failed(s.error().message);
    return fail(*store_refusal(), &job);
  }
  event(job, "state", {{"from", nullptr}, {"to", "queued"}, {"reason", "submitted"},
                       {"source", r.move_into_job ? nlohmann::json("upload") : nlohmann::json(r.model_path)},
                       {"by", r.by.user}, {"role", role_name(r.by.role)}});
  jobs_log()->info("job {}: queued ({}, from {})", job.id, job.model_path, r.move_into_job ? "an upload" : r.model_path);
  jobs_[job.id] = job;
  plan_queue_.push_back(job.id);
  plan_wake_.notify_one();
  announce(job);
  return job;
}

std::vector<JobRecord> JobManager::list() const {
  std::lock_guard lock(mutex_);
  std::vector<JobRecord> out;
  for (const auto& [id, job] : jobs_) out.push_back(job);
  std::sort(out.begin(), out.end(), [](const JobRecord& a, const JobRecord& b) {
    return a.created_unix_ms != b.created_unix_ms ? a.created_unix_ms < b.created_unix_ms : a.id < b.id;
  });
  return out;
}

std::expected<JobRecord, JobError> JobManager::get(const std::string& id) const {
  std::lock_guard lock(mutex_);
  const JobRecord* job = find(id);
  if (!job) return std::unexpected(job_error(JobErrorKind::not_found, fmt::format("no job {}", id)));
  return *job;
}

std::expected<std::vector<JobEvent>, JobError> JobManager::events(const std::string& id) const {
  if (!get(id)) return std::unexpected(job_error(JobErrorKind::not_found, fmt::format("no job {}", id)));
  auto events = store_.events(id);  // the store locks itself: not under mutex_
  if (!events) return std::unexpected(job_error(JobErrorKind::storage, events.error().message));
  return std::move(*events);
}

std::expected<JobRecord, JobError> JobManager::cancel(const std::string& id, const Actor& by) {
  std::shared_ptr<drivers::CutJob> cut;
  JobRecord copy;
  {
    std::lock_guard lock(mutex_);
    JobRecord* job = find(id);
    if (!job) return std::unexpected(job_error(JobErrorKind::not_found, fmt::format("no job {}", id)));
    if (auto refused = store_refusal()) return std::unexpected(*refused);  // machine.abort stops a cut all the same
    if (is_terminal(job->state))
      return std::unexpected(job_error(JobErrorKind::wrong_state, fmt::format("job {} is already {}", id, to_string(job->state))));
    action(*job, "cancel", by);
    if (job->state == JobState::planning) {
      if (auto it = plan_cancel_.find(id); it != plan_cancel_.end()) it->second->store(true);
      return *job;  // the planner worker marks it cancelled when the child has stopped
    }
    if (id == machine_job_ && cutting_) {
      cancel_after_stop_ = id;
      cut = cut_;
      copy = *job;
    } else {
      std::erase(plan_queue_, id);
      const bool owned = id == machine_job_;
      if (auto s = set_state(*job, JobState::cancelled, "cancelled by the operator"); !s) return std::unexpected(s.error());
      if (owned) {
        machine_job_.clear();
        cut_.reset();
        // The stop left the pump running for a resume; nobody will resume now. Blocking Modbus
        // work stays off the io thread. The cutter slot is free: nothing is cutting, and a
        // cutter that ended on the fault has left finish_cut (cutting_ is false) — join it, or
        // the pump and abrasive stayed on (a joinable cutter used to skip this).
        if (machine_.cell()) {
          if (cutter_.joinable()) cutter_.join();
          cutter_ = std::thread([cell = machine_.cell()] { (void)cell->finish_cut(); });
        }
        assign_machine();
      }
      return *job;
    }
  }
  cut->abort("job cancelled by the operator");  // the cutting thread finishes the cancel
  return copy;
}

std::expected<JobRecord, JobError> JobManager::confirm_sheet(const std::string& id, int sheet, const Actor& by) {
  const ProgramRead program = read_current_program(id);
  std::lock_guard lock(mutex_);
  JobRecord* job = find(id);
  if (!job) return std::unexpected(job_error(JobErrorKind::not_found, fmt::format("no job {}", id)));
  if (job->state != JobState::waiting_sheet)
    return std::unexpected(job_error(JobErrorKind::wrong_state,
                                 fmt::format("job {} is {}, not waiting for a sheet", id, to_string(job->state))));
  if (sheet != job->current_sheet)
    return std::unexpected(job_error(JobErrorKind::bad_request,
                                 fmt::format("sheet {}: job {} waits for sheet {}", sheet, id, job->current_sheet)));
  action(*job, "confirm_sheet", by, {{"sheet", sheet}});
  if (auto started = start_cut(*job, CutStart::fresh, program); !started) return std::unexpected(started.error());
  return *job;
}

std::expected<JobRecord, JobError> JobManager::resume(const std::string& id, const Actor& by) {
  const ProgramRead program = read_current_program(id);
  std::lock_guard lock(mutex_);
  JobRecord* job = find(id);
  if (!job) return std::unexpected(job_error(JobErrorKind::not_found, fmt::format("no job {}", id)));
  if (auto refused = store_refusal()) return std::unexpected(*refused);
  if (job->state == JobState::paused || job->state == JobState::interrupted) action(*job, "resume", by);
  if (job->state == JobState::paused && pause_ == PauseKind::hold && cutting_) {
    std::shared_ptr<drivers::CutJob> cut = cut_;
    cut->continue_motion();  // jet on again first, then the cycle start (line and PLC): CutJob's hold watch
    pause_ = PauseKind::none;
    (void)set_state(*job, JobState::cutting);
    return *job;
  }
  if (job->state == JobState::paused) {
    if (cutting_) return std::unexpected(job_error(JobErrorKind::machine_busy, "the cut is still stopping; try again"));
    if (auto started = start_cut(*job, CutStart::resume_stopped, program); !started) return std::unexpected(started.error());
    return *job;
  }
  if (job->state == JobState::interrupted) {
    if (!machine_job_.empty() && machine_job_ != id)
      return std::unexpected(job_error(JobErrorKind::machine_busy, fmt::format("the machine is with job {}", machine_job_)));
    if (auto started = start_cut(*job, CutStart::resume_interrupted, program); !started) return std::unexpected(started.error());
    machine_job_ = id;
    return *job;
  }
  return std::unexpected(job_error(JobErrorKind::wrong_state,
                               fmt::format("job {} is {}: only paused or interrupted jobs resume", id, to_string(job->state))));
}

nlohmann::json JobManager::machine_status() {
  nlohmann::json status = machine_.status();
  const auto file = store_.check_file();  // a database deleted while nothing writes is noticed here
  std::lock_guard lock(mutex_);
  if (!file) store_failed(file.error().message);
  status["store"] = {{"ok", !store_fault_}, {"error", store_fault_ ? nlohmann::json(*store_fault_) : nlohmann::json(nullptr)}};
  status["job"] = machine_job_.empty() ? nlohmann::json(nullptr) : nlohmann::json(machine_job_);
  if (const JobRecord* job = find(machine_job_)) {
    status["job_state"] = to_string(job->state);
    status["sheet"] = job->current_sheet;
    for (const SheetRecord& s : job->sheets)
      if (s.index == job->current_sheet) status["program_line"] = s.last_acked_line;
  }
  return status;
}

// The machine first, the bookkeeping after: the hold reaches the line and the PLC without
// waiting for the database (a synced write) or for anyone holding the lock.
std::expected<nlohmann::json, JobError> JobManager::hold(const Actor& by) {
  std::shared_ptr<drivers::CutJob> cut;
  {
    std::lock_guard lock(mutex_);
    JobRecord* job = find(machine_job_);
    if (!job || job->state != JobState::cutting || !cutting_)
      return std::unexpected(job_error(JobErrorKind::wrong_state, "nothing is cutting"));
    cut = cut_;
  }
  cut->hold();  // the line's real-time byte and the PLC's button (a drip feed has no hold on its line)
  std::lock_guard lock(mutex_);
  if (JobRecord* job = find(machine_job_); job && job->state == JobState::cutting && cutting_ && cut_ == cut) {
    action(*job, "hold", by);
    pause_ = PauseKind::hold;
    (void)set_state(*job, JobState::paused, "held by the operator");
  }
  return nlohmann::json{{"held", true}};
}

std::expected<nlohmann::json, JobError> JobManager::resume_motion(const Actor& by) {
  std::string id;
  {
    std::lock_guard lock(mutex_);
    id = machine_job_;
  }
  if (id.empty()) return std::unexpected(job_error(JobErrorKind::wrong_state, "no job has the machine"));
  auto r = resume(id, by);
  if (!r) return std::unexpected(r.error());
  return to_json(*r);
}

std::expected<nlohmann::json, JobError> JobManager::abort(const std::string& why, const Actor& by) {
  std::shared_ptr<drivers::CutJob> cut;
  {
    std::lock_guard lock(mutex_);
    if (!cutting_) return std::unexpected(job_error(JobErrorKind::wrong_state, "nothing is cutting"));
    if (const JobRecord* job = find(machine_job_)) action(*job, "abort", by, {{"reason", why}});
    cut = cut_;
  }
  cut->abort(why);  // the cut stops safely; its job becomes paused with a resume point
  return nlohmann::json{{"aborted", true}};
}

std::string JobManager::status_line() const {
  std::lock_guard lock(mutex_);
  int queued = 0;
  for (const auto& [id, job] : jobs_) queued += job.state == JobState::queued || job.state == JobState::planned;
  const JobRecord* job = find(machine_job_);
  if (!job) return fmt::format("idle, {} job(s) waiting", queued);
  return fmt::format("job {} {} sheet {}/{}, {} waiting", job->id, to_string(job->state), job->current_sheet,
                     job->sheets.size(), queued);
}

// ---------------------------------------------------------------------------- planning

void JobManager::planner_loop() {
  while (true) {
    std::string id;
    {
      std::unique_lock lock(mutex_);
      plan_wake_.wait(lock, [this] { return stopping_ || !plan_queue_.empty(); });
      if (stopping_) return;
      id = plan_queue_.front();
      plan_queue_.pop_front();
    }
    plan_job(id);
  }
}

// The plan's sheets and summary into the job (under mutex_); false when it has no sheet.
bool JobManager::take_plan(JobRecord& job, const PlanReport& r) {
  job.sheets.clear();
  std::size_t lines = 0;
  double estimate_s = 0;
  for (const ReportSheet& s : r.sheets.value_or(std::vector<ReportSheet>{})) {
    SheetRecord sheet;
    sheet.index = static_cast<int>(s.index);
    sheet.program_path = (fs::path(job.artefact_dir) / s.program).string();
    sheet.svg_path = (fs::path(job.artefact_dir) / s.svg).string();
    sheet.material = s.material;
    sheet.thickness_mm = s.thickness_mm;
    std::ifstream in(sheet.program_path);
    for (std::string line; std::getline(in, line);) sheet.lines_total += !line.empty() && line != "\r";
    lines += sheet.lines_total;
    estimate_s += s.estimated_time_s;
    job.sheets.push_back(std::move(sheet));
  }
  if (job.sheets.empty()) return false;
  nlohmann::json deviation = nlohmann::json::object();
  for (const auto& [strategy, d] : r.deviation) deviation[strategy] = {{"volume_pct", d.volume_pct}, {"max_mm", d.max_mm}};
  job.summary = {{"layers", r.layers.size()},
                 {"sheets", job.sheets.size()},
                 {"lines", lines},
                 {"estimated_cut_s", estimate_s},
                 {"deviation", deviation},
                 {"stack", (fs::path(job.artefact_dir) / "stack.stl").string()},
                 {"report", (fs::path(job.artefact_dir) / "report.json").string()},
                 {"warnings", r.warnings}};
  return true;
}

void JobManager::plan_job(const std::string& id) {
  auto cancel = std::make_shared<std::atomic<bool>>(false);
  PlanProcessRequest request;
  {
    std::lock_guard lock(mutex_);
    JobRecord* job = find(id);
    if (!job || job->state != JobState::queued) return;
    plan_cancel_[id] = cancel;
    if (!set_state(*job, JobState::planning)) return;
    request.lamina = config_.planner.lamina_path;
    request.model = job->model_path;
    request.out_dir = job->artefact_dir;
    request.flags = plan_args_from_settings(job->plan_settings).value_or(PlanArgs{}).flags;
    if (!config_.planner.machine_file.empty()) request.flags.insert(request.flags.end(), {"--machine", config_.planner.machine_file});
    if (!config_.planner.materials_file.empty())
      request.flags.insert(request.flags.end(), {"--materials", config_.planner.materials_file});
    request.timeout_s = config_.planner.timeout_s;
    request.limits = {config_.planner.memory_limit_mb << 20, config_.planner.cpu_limit_s, config_.planner.nice};
  }
  auto report = run_plan_process(request, *cancel, [this, &id](const nlohmann::json& phase) {
    nlohmann::json j;
    {
      std::lock_guard lock(mutex_);
      JobRecord* job = find(id);
      if (!job || job->state != JobState::planning) return;
      job->planning = {{"phase", phase.value("phase", "")}, {"step", phase.value("step", 0)},
                       {"steps", phase.value("steps", 0)}};
      if (phase.contains("total"))  // a step inside the phase (issue 18): the bar moves within it
        job->planning.update({{"done", phase.value("done", 0)}, {"total", phase.value("total", 0)}});
      j = to_json(*job);
    }
    if (notify_) notify_("notify_job_progress", j);
  });

  std::lock_guard lock(mutex_);
  plan_cancel_.erase(id);
  JobRecord* job = find(id);
  if (!job) return;
  job->planning = nullptr;
  if (!report) {
    if (stopping_ && !report.error().cancelled) return;
    if (report.error().cancelled && stopping_) {
      (void)set_state(*job, JobState::queued, "planning stopped with the daemon; planned again at start");
      return;
    }
    (void)set_state(*job, report.error().cancelled ? JobState::cancelled : JobState::failed, report.error().message);
    return;
  }
  if (!take_plan(*job, *report)) {
    (void)set_state(*job, JobState::failed, "the plan has no sheets to cut (see plan.log)");
    return;
  }
  (void)set_state(*job, JobState::planned);
  assign_machine();
}

}  // namespace lamina::daemon
