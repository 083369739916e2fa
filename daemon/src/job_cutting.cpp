// JobManager, the cutting half: one thread streams the current sheet through the machine link
// (drivers::CutJob), saves its progress (the crash-safe record of where it is) and turns the
// outcome into the job's next state.
#include <chrono>
#include <filesystem>
#include <fstream>
#include <thread>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "job_manager.hpp"
#include "lamina/drivers/resume_point.hpp"

namespace lamina::daemon {
namespace {

using Clock = std::chrono::steady_clock;

std::shared_ptr<spdlog::logger> cut_log() {
  static auto logger = [] {
    auto l = spdlog::get("cut");
    return l ? l : spdlog::default_logger()->clone("cut");
  }();
  return logger;
}

}  // namespace

std::vector<std::string> JobManager::read_program(const std::string& path) {
  std::vector<std::string> lines;
  std::ifstream in(path);
  for (std::string line; std::getline(in, line);) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (!line.empty()) lines.push_back(line);  // as lamina stream: a blank line means nothing to a controller
  }
  return lines;
}

namespace {

SheetRecord* sheet_of(JobRecord& job, int index) {
  for (SheetRecord& s : job.sheets)
    if (s.index == index) return &s;
  return nullptr;
}

// The sheet's program map as the post handed it over (report.json's contour_lines: issue 18), for
// the resume point. The program must still be the one planned: its line count is checked.
std::expected<drivers::ProgramMap, std::string> program_map_of(const std::string& artefact_dir, int sheet_index,
                                                               std::size_t program_lines) {
  const std::string path = (std::filesystem::path(artefact_dir) / "report.json").string();
  std::ifstream in(path, std::ios::binary);
  if (!in) return std::unexpected(fmt::format("{}: cannot read the plan's report", path));
  auto report = parse_plan_report(std::string{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()});
  if (!report) return std::unexpected(report.error().message);
  for (const ReportSheet& s : report->sheets.value_or(std::vector<ReportSheet>{})) {
    if (s.index != sheet_index) continue;
    if (s.program_lines != static_cast<std::int64_t>(program_lines))
      return std::unexpected(fmt::format("{} has {} lines, the plan made {}: it changed since it was planned", s.program,
                                         program_lines, s.program_lines));
    drivers::ProgramMap map;
    map.setup_end = static_cast<std::size_t>(s.setup_lines);
    for (const ReportContour& c : s.contour_lines)
      map.contours.push_back({static_cast<int>(c.index), static_cast<std::size_t>(c.line - 1),
                              c.last_cut_line > 0 ? std::optional(static_cast<std::size_t>(c.last_cut_line - 1))
                                                  : std::nullopt});
    return map;
  }
  return std::unexpected(fmt::format("{}: no sheet {}", path, sheet_index));
}

bool still(drivers::ControllerState s) {
  using S = drivers::ControllerState;
  return s == S::idle || s == S::hold || s == S::alarm || s == S::door;
}

}  // namespace

JobManager::ProgramRead JobManager::read_current_program(const std::string& job_id) const {
  ProgramRead read;
  std::string artefact_dir;
  int sheet = 0;
  {
    std::lock_guard lock(mutex_);
    const JobRecord* job = find(job_id);
    if (!job) return read;
    for (const SheetRecord& s : job->sheets)
      if (s.index == job->current_sheet) read.path = s.program_path, sheet = s.index;
    artefact_dir = job->artefact_dir;
  }
  if (read.path.empty()) return read;
  read.lines = read_program(read.path);
  read.map = program_map_of(artefact_dir, sheet, read.lines.size());
  return read;
}

// Under mutex_. Joins the previous cutting thread (it has left finish_cut: cutting_ is false).
// Nothing moves unless the database has taken the job's `cutting` first: a cut it does not know
// of would be cut again after a crash.
std::expected<void, JobError> JobManager::start_cut(JobRecord& job, CutStart how, const ProgramRead& read) {
  if (cutter_.joinable()) cutter_.join();
  SheetRecord* sheet = sheet_of(job, job.current_sheet);
  if (!sheet) return std::unexpected(JobError{JobErrorKind::internal, fmt::format("job {} has no sheet {}", job.id, job.current_sheet)});
  // Read before the lock was taken (a long program must not hold up the operator's hold); again
  // here only if the sheet changed meanwhile.
  const bool same = read.path == sheet->program_path;
  std::vector<std::string> program = same ? read.lines : read_program(sheet->program_path);
  if (program.empty()) {
    const std::string why = fmt::format("{}: no program lines", sheet->program_path);
    (void)set_state(job, JobState::interrupted, why);
    return std::unexpected(JobError{JobErrorKind::wrong_state, why});
  }
  auto map = same ? read.map : program_map_of(job.artefact_dir, sheet->index, program.size());
  if (!map) {  // no safe resume point could be known: nothing is cut
    (void)set_state(job, JobState::interrupted, map.error());
    return std::unexpected(JobError{JobErrorKind::wrong_state, map.error()});
  }
  const SheetState sheet_before = sheet->state;
  sheet->state = SheetState::cutting;
  if (auto written = set_state(job, JobState::cutting); !written) {
    if (SheetRecord* s = sheet_of(job, job.current_sheet)) s->state = sheet_before;  // reload may have done it
    return std::unexpected(written.error());
  }
  sheet = sheet_of(job, job.current_sheet);
  if (how != CutStart::resume_stopped || !cut_) {
    drivers::CutJobSettings settings = machine_.cut_settings();
    settings.program_map = std::move(*map);
    cut_ = std::make_shared<drivers::CutJob>(machine_.link(), machine_.cell(), program, std::move(settings));
  }
  if (how == CutStart::resume_stopped && cut_->report().state != drivers::CutState::stopped) how = CutStart::fresh;
  cutting_ = true;
  pause_ = PauseKind::none;
  cut_->on_progress([this, id = job.id, index = sheet->index](const drivers::CutReport& r) { save_progress(id, index, r); });
  cut_->on_hold([this, id = job.id](const drivers::LinkError& why) { machine_held(id, why); });
  cutter_ = std::thread([this, id = job.id, index = sheet->index, how, program = std::move(program)]() mutable {
    cut_sheet(id, index, how, std::move(program), std::nullopt);
  });
  return {};
}

void JobManager::cut_sheet(std::string job_id, int sheet_index, CutStart how, std::vector<std::string> program,
                           std::optional<std::size_t>) {
  drivers::CutJob& cut = *cut_;  // replaced only by start_cut, after this thread is joined
  drivers::CutReport report;
  if (how == CutStart::fresh) {
    cut_log()->info("job {}: cutting sheet {} ({} lines)", job_id, sheet_index, program.size());
    report = cut.run();
  } else if (how == CutStart::resume_stopped) {
    cut_log()->info("job {}: resuming sheet {}", job_id, sheet_index);
    report = cut.resume();
  } else {
    // After a restart: connect, make sure nothing moves, read where the CNC got to.
    machine_.link().start(drivers::LineSpan{{}, 0}, {});
    (void)machine_.link().wait(10);
    machine_.link().request(drivers::RealtimeCommand::feed_hold);
    // The PLC's button too, and wait until it has acted: the resume below resets the CNC over
    // its line, and a press handed on after that reset would leave the restarted program held.
    if (machine_.cell())
      if (auto held = machine_.cell()->hold_cnc(); !held) cut_log()->warn("job {}: feed hold through the PLC: {}", job_id, held.error().message);
    SheetRecord sheet;
    {
      std::lock_guard lock(mutex_);
      if (JobRecord* job = find(job_id))
        if (SheetRecord* s = sheet_of(*job, sheet_index)) sheet = *s;
    }
    std::string note;
    const std::size_t line = interrupted_resume_line(sheet, program, note);
    {
      std::lock_guard lock(mutex_);
      if (JobRecord* job = find(job_id)) event(*job, "resume", {{"sheet", sheet_index}, {"first_unfinished_line", line + 1}, {"how", note}});
    }
    cut_log()->info("job {}: resuming interrupted sheet {} near line {} ({})", job_id, sheet_index, line + 1, note);
    report = cut.resume_from(line);
  }
  finish_cut(job_id, sheet_index, report);
}

// Where an interrupted sheet starts again. The CNC's executed-block count (through the PLC)
// against the count saved when the attempt started says exactly which line was running; the
// cut then restarts at the start of that line's contour (CutJob::resume_from).
std::size_t JobManager::interrupted_resume_line(const SheetRecord& sheet, const std::vector<std::string>& program,
                                                std::string& note) {
  drivers::CellIo* cell = machine_.cell();
  if (cell && sheet.executed_base) {
    // Wait for the machine to stand still (the hold just sent), then read its count.
    const auto deadline = Clock::now() + std::chrono::seconds(5);
    while (Clock::now() < deadline) {
      if (cell->refresh() && still(cell->status().cnc_state)) break;
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    const auto count = cell->status().cnc_executed_blocks;
    const std::uint64_t first = *sheet.executed_base + sheet.attempt_preamble_lines;
    if (count && *count >= first) {
      const std::size_t ran = static_cast<std::size_t>(*count - first);
      // The count alone: the saved acknowledged line is up to one save period old (200 ms), so
      // capping by it put the resume before a contour that had finished since — and cut it twice.
      const std::size_t line = std::min(sheet.attempt_first_line + ran, program.size());
      note = fmt::format("placed by the CNC's executed-block count ({} since the attempt began)", ran);
      return line;
    }
    note = "the CNC's executed-block count went back (was it restarted?): from the last acknowledged line's contour";
  } else {
    note = "no executed-block count (no PLC): from the last acknowledged line's contour; check the part";
  }
  return sheet.last_acked_line > 0 ? sheet.last_acked_line - 1 : 0;
}

// A hold the operator did not ask for through us — the machine ran dry with the jet on and the
// job held it, or the PLC's or the controller's own hold button — with the jet off: the job is
// paused as by machine.hold, so job.resume / machine.resume opens the jet and continues.
void JobManager::machine_held(const std::string& job_id, const drivers::LinkError& why) {
  std::lock_guard lock(mutex_);
  JobRecord* job = find(job_id);
  if (!job || job->state != JobState::cutting || !cutting_) return;
  cut_log()->warn("job {}: held: {}", job_id, why.message);
  pause_ = PauseKind::hold;
  (void)set_state(*job, JobState::paused, why.message);
}

void JobManager::save_progress(const std::string& job_id, int sheet_index, const drivers::CutReport& r) {
  const auto now = Clock::now();
  SheetRecord copy;
  bool announce_now = false;
  JobRecord job_copy;
  {
    std::lock_guard lock(mutex_);
    if (now - last_saved_ < std::chrono::milliseconds(200)) return;
    last_saved_ = now;
    JobRecord* job = find(job_id);
    SheetRecord* sheet = job ? sheet_of(*job, sheet_index) : nullptr;
    if (!sheet) return;
    sheet->last_acked_line = r.lines_accepted;
    sheet->executed_base = r.executed_base;
    sheet->attempt_first_line = r.attempt_first_line;
    sheet->attempt_preamble_lines = r.attempt_preamble_lines;
    copy = *sheet;
    if (now - last_announced_ >= std::chrono::milliseconds(500)) {
      last_announced_ = now;
      announce_now = true;
      job_copy = *job;
    }
  }
  if (auto s = store_.update_sheet(job_id, copy); !s) {
    std::lock_guard lock(mutex_);
    store_failed(s.error().message);  // stops the cut
    if (JobRecord* job = find(job_id)) reload(*job);
    return;
  }
  if (announce_now && notify_) {
    nlohmann::json j = to_json(job_copy);
    j["progress"] = {{"sheet", sheet_index}, {"lines_accepted", r.lines_accepted}, {"lines", r.lines_total}};
    notify_("notify_job_progress", j);
  }
}

void JobManager::finish_cut(const std::string& job_id, int sheet_index, const drivers::CutReport& r) {
  bool make_cell_safe = false;
  {
    std::lock_guard lock(mutex_);
    cutting_ = false;
    JobRecord* job = find(job_id);
    SheetRecord* sheet = job ? sheet_of(*job, sheet_index) : nullptr;
    if (!sheet) return;
    sheet->last_acked_line = r.lines_accepted;
    sheet->first_unfinished_line = r.first_unfinished_line;
    sheet->contour = r.resume ? r.resume->contour : -1;
    sheet->executed_base = r.executed_base;
    sheet->attempt_first_line = r.attempt_first_line;
    sheet->attempt_preamble_lines = r.attempt_preamble_lines;
    sheet->cut_seconds = r.seconds;
    const std::string why = r.reason ? r.reason->message : std::string();
    if (r.state == drivers::CutState::completed) {
      sheet->state = SheetState::done;
      event(*job, "sheet", {{"sheet", sheet_index}, {"state", "done"}, {"lines", r.lines_total}, {"seconds", r.seconds}});
      int next = 0;
      for (const SheetRecord& s : job->sheets)
        if (s.state != SheetState::done) {
          next = s.index;
          break;
        }
      if (next == 0) {
        (void)set_state(*job, JobState::completed);
        machine_job_.clear();
        cut_.reset();
        assign_machine();
      } else {
        (void)set_state(*job, JobState::sheet_done, fmt::format("sheet {} done", sheet_index));
        job->current_sheet = next;
        (void)set_state(*job, JobState::waiting_sheet, fmt::format("load sheet {} and confirm it", next));
      }
    } else if (cancel_after_stop_ == job_id) {
      cancel_after_stop_.clear();
      sheet->state = SheetState::interrupted;
      (void)set_state(*job, JobState::cancelled, "cancelled by the operator while cutting");
      machine_job_.clear();
      make_cell_safe = true;
      assign_machine();
    } else if (stopping_) {
      sheet->state = SheetState::interrupted;
      (void)set_state(*job, JobState::interrupted, why.empty() ? "the daemon stopped" : why);
      make_cell_safe = true;
    } else {
      // Stopped by a fault or the operator's abort (or the cell would not come up): the job
      // waits, held, for job.resume or job.cancel. Nothing restarts by itself.
      sheet->state = SheetState::paused;
      pause_ = PauseKind::stopped;
      if (r.state == drivers::CutState::failed) cut_.reset();  // nothing streamed: the next try runs afresh
      (void)set_state(*job, JobState::paused, why.empty() ? "stopped" : why);
      event(*job, "fault", {{"sheet", sheet_index}, {"reason", why},
                            {"code", r.reason ? drivers::to_string(r.reason->code) : ""},
                            {"resume_line", r.resume ? nlohmann::json(r.resume->restart_index + 1) : nlohmann::json(nullptr)}});
    }
  }
  if (make_cell_safe && machine_.cell()) (void)machine_.cell()->finish_cut();
}

}  // namespace lamina::daemon
