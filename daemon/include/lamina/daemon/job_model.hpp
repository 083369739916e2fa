#pragma once
// The job as the daemon keeps it: plain data, stored in SQLite (job_store.hpp), sent over
// JSON-RPC (docs/api.md). States and their transitions: docs/api.md "Job states".
#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace lamina::daemon {

// The wall clock's time as the job's timestamps hold it (`*_unix_ms`).
inline std::int64_t now_unix_ms() {
  using namespace std::chrono;
  return duration_cast<milliseconds>(system_clock::now().time_since_epoch()).count();
}

enum class JobState {
  queued,         // accepted, waiting for the planner
  planning,       // the planner runs (a worker; cancellable)
  planned,        // programs written; waiting for the machine
  waiting_sheet,  // the operator must load sheet `current_sheet` and confirm it
  cutting,        // the sheet's program streams
  paused,         // held (operator or fault); resumes only on request
  sheet_done,     // a sheet finished; the next one follows (waiting_sheet) or the job completes
  completed,
  failed,         // planning failed, or the machine refused the job; `error` says why
  cancelled,
  interrupted,    // the daemon stopped (crash, power loss, SIGTERM) while cutting; job.resume continues
};

const char* to_string(JobState state);
std::optional<JobState> job_state_from_string(const std::string& text);
bool is_terminal(JobState state);  // completed, failed, cancelled

enum class SheetState { pending, cutting, paused, done, interrupted };
const char* to_string(SheetState state);
std::optional<SheetState> sheet_state_from_string(const std::string& text);

struct SheetRecord {
  int index = 0;                     // 1-based, as in sheet-<n>.nc
  std::string program_path;          // absolute
  std::string svg_path;
  std::string material;
  double thickness_mm = 0;
  std::size_t lines_total = 0;
  SheetState state = SheetState::pending;
  // Progress of the last attempt, persisted while cutting (the crash-safe part):
  std::size_t last_acked_line = 0;   // 1-based program line the controller last acknowledged (0: none)
  std::size_t first_unfinished_line = 0;  // 0-based index; where a resume starts its search
  int contour = -1;                  // contour of first_unfinished_line (-1: before the first)
  std::optional<std::uint64_t> executed_base;  // PLC's executed-block count when this attempt started
  std::size_t attempt_first_line = 0;          // 0-based program index the attempt streamed from
  std::size_t attempt_preamble_lines = 0;      // lines sent before it (resume preamble)
  double cut_seconds = 0;
};

struct JobRecord {
  std::string id;                  // "j-<unix ms>-<4 hex>", sortable by creation
  JobState state = JobState::queued;
  std::string model_path;          // on the cell PC (an upload is stored under jobs/<id>/)
  std::string name;                // the model's file name, for people
  nlohmann::json plan_settings = nlohmann::json::object();  // as submitted (validated)
  std::string artefact_dir;        // jobs/<id>/
  std::string error;               // why failed / interrupted / paused
  int current_sheet = 0;           // 1-based; 0 before the first
  std::vector<SheetRecord> sheets;
  nlohmann::json summary = nlohmann::json::object();  // from the plan report: layers, sheets, lines, deviation…
  std::int64_t created_unix_ms = 0;
  std::int64_t updated_unix_ms = 0;
  // While planning: the planner's last phase {phase, step, steps}. Not stored: a restart plans
  // the job again from the start.
  nlohmann::json planning = nullptr;
};

struct JobEvent {
  std::string job_id;
  std::int64_t t_unix_ms = 0;
  std::string kind;                // "state", "sheet", "fault", "note"…
  nlohmann::json data = nlohmann::json::object();
};

nlohmann::json to_json(const SheetRecord& sheet);
nlohmann::json to_json(const JobRecord& job);  // what job.get returns
nlohmann::json to_json(const JobEvent& event);

}  // namespace lamina::daemon
