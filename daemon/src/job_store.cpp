#include "lamina/daemon/job_store.hpp"

#include <chrono>
#include <cstdint>
#include <mutex>
#include <string_view>
#include <utility>

#include <fmt/core.h>

#include "sqlite_connection.hpp"

namespace lamina::daemon {
namespace {

constexpr int kSchemaVersion = 1;

// Constant text only (no values), so sqlite3_exec is fine here. STRICT makes SQLite refuse a
// value of the wrong type instead of silently storing it. executed_base is a uint64 stored as
// its int64 bit pattern (SQLite has no unsigned integers); NULL means "not known".
constexpr const char* kSchema = R"sql(
CREATE TABLE jobs (
  id TEXT PRIMARY KEY NOT NULL,
  state TEXT NOT NULL,
  model_path TEXT NOT NULL,
  name TEXT NOT NULL,
  plan_settings TEXT NOT NULL,
  artefact_dir TEXT NOT NULL,
  error TEXT NOT NULL,
  current_sheet INTEGER NOT NULL,
  summary TEXT NOT NULL,
  created_unix_ms INTEGER NOT NULL,
  updated_unix_ms INTEGER NOT NULL
) STRICT;
CREATE INDEX jobs_by_creation ON jobs (created_unix_ms, id);
CREATE TABLE sheets (
  job_id TEXT NOT NULL REFERENCES jobs (id) ON DELETE CASCADE,
  idx INTEGER NOT NULL,
  program_path TEXT NOT NULL,
  svg_path TEXT NOT NULL,
  material TEXT NOT NULL,
  thickness_mm REAL NOT NULL,
  lines_total INTEGER NOT NULL,
  state TEXT NOT NULL,
  last_acked_line INTEGER NOT NULL,
  first_unfinished_line INTEGER NOT NULL,
  contour INTEGER NOT NULL,
  executed_base INTEGER,
  attempt_first_line INTEGER NOT NULL,
  attempt_preamble_lines INTEGER NOT NULL,
  cut_seconds REAL NOT NULL,
  PRIMARY KEY (job_id, idx)
) STRICT;
CREATE TABLE events (
  id INTEGER PRIMARY KEY AUTOINCREMENT,
  job_id TEXT NOT NULL REFERENCES jobs (id) ON DELETE CASCADE,
  t_unix_ms INTEGER NOT NULL,
  kind TEXT NOT NULL,
  data TEXT NOT NULL
) STRICT;
CREATE INDEX events_by_job ON events (job_id, id);
PRAGMA user_version = 1;
)sql";

// Numbered parameters: the insert and the update bind the same sequence (id first).
constexpr const char* kInsertJob =
    "INSERT INTO jobs (id, state, model_path, name, plan_settings, artefact_dir, error, current_sheet, summary,"
    " created_unix_ms, updated_unix_ms) VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9, ?10, ?11)";
constexpr const char* kUpdateJob =
    "UPDATE jobs SET state = ?2, model_path = ?3, name = ?4, plan_settings = ?5, artefact_dir = ?6, error = ?7,"
    " current_sheet = ?8, summary = ?9, created_unix_ms = ?10, updated_unix_ms = ?11 WHERE id = ?1";
constexpr const char* kSelectJob =
    "SELECT id, state, model_path, name, plan_settings, artefact_dir, error, current_sheet, summary,"
    " created_unix_ms, updated_unix_ms FROM jobs WHERE id = ?1";
constexpr const char* kSelectJobs =
    "SELECT id, state, model_path, name, plan_settings, artefact_dir, error, current_sheet, summary,"
    " created_unix_ms, updated_unix_ms FROM jobs ORDER BY created_unix_ms, id";
constexpr const char* kInsertSheet =
    "INSERT INTO sheets (job_id, idx, program_path, svg_path, material, thickness_mm, lines_total, state,"
    " last_acked_line, first_unfinished_line, contour, executed_base, attempt_first_line, attempt_preamble_lines,"
    " cut_seconds) VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9, ?10, ?11, ?12, ?13, ?14, ?15)";
constexpr const char* kSelectSheets =
    "SELECT idx, program_path, svg_path, material, thickness_mm, lines_total, state, last_acked_line,"
    " first_unfinished_line, contour, executed_base, attempt_first_line, attempt_preamble_lines, cut_seconds"
    " FROM sheets WHERE job_id = ?1 ORDER BY idx";
constexpr const char* kUpdateSheetProgress =
    "UPDATE sheets SET state = ?3, last_acked_line = ?4, first_unfinished_line = ?5, contour = ?6,"
    " executed_base = ?7, attempt_first_line = ?8, attempt_preamble_lines = ?9, cut_seconds = ?10"
    " WHERE job_id = ?1 AND idx = ?2";
constexpr const char* kInsertEvent = "INSERT INTO events (job_id, t_unix_ms, kind, data) VALUES (?1, ?2, ?3, ?4)";

using sqlite::Connection;
using Access = sqlite::Connection::Access;
using sqlite::Fail;
using sqlite::Statement;

std::string dump(const nlohmann::json& value) {
  // `replace`: a string with invalid UTF-8 must not make a store call throw.
  return value.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

// The store's own settings and schema on a freshly opened connection. Errors name the file.
std::expected<void, StoreError> prepare_database(Connection& db) {
  auto fail = [&](std::string_view what) {
    return Fail(StoreError{fmt::format("{}: open: {}", db.path().string(), what)});
  };
  // The version first: a newer file must not even be switched to WAL. A file that is not a
  // database fails here ("file is not a database").
  auto version = db.single_integer("PRAGMA user_version", "read the schema version");
  if (!version) return fail(version.error().message);
  if (*version > kSchemaVersion)
    return fail(fmt::format("schema version {} is newer than this laminad understands ({}); use a newer laminad",
                            *version, kSchemaVersion));
  {
    auto mode = db.statement("PRAGMA journal_mode = WAL", "switch to WAL");
    if (!mode) return fail(mode.error().message);
    auto row = mode->step();
    if (!row) return fail(row.error().message);
    if (!*row || mode->text(0) != "wal")
      return fail(fmt::format("the journal mode stays '{}' (WAL needed)", *row ? mode->text(0) : ""));
  }
  // FULL: each commit is fsynced, so a state change survives a power loss, not only a crash of
  // laminad. NORMAL could lose the last commits, e.g. a `completed` that would then be
  // recovered as `interrupted` and offered for resume. The cost is one WAL fsync per call
  // (update_sheet: a few per second), acceptable on the cell PC.
  for (const char* pragma : {"PRAGMA synchronous = FULL", "PRAGMA foreign_keys = ON"})
    if (auto set = db.run(pragma, pragma); !set) return fail(set.error().message);
  if (*version == kSchemaVersion) return {};

  // BEGIN IMMEDIATE and a second look: another process may have created the schema meanwhile.
  return db.transaction("open: create the schema", Access::write, [&]() -> std::expected<void, StoreError> {
    auto again = db.single_integer("PRAGMA user_version", "read the schema version");
    if (!again) return Fail(again.error());
    if (*again == kSchemaVersion) return {};
    // A version-0 file with tables is someone else's database: do not add ours to it.
    auto objects = db.single_integer("SELECT count(*) FROM sqlite_schema", "read the schema");
    if (!objects) return Fail(objects.error());
    if (*objects != 0) return Fail(StoreError{"not a Lamina job database (other tables, no schema version)"});
    return db.run_script(kSchema, "create the tables");
  });
}

// --- rows ------------------------------------------------------------------------------------

void bind_job(Statement& s, const JobRecord& job) {
  s.bind(job.id).bind(to_string(job.state)).bind(job.model_path).bind(job.name).bind(dump(job.plan_settings));
  s.bind(job.artefact_dir).bind(job.error).bind(job.current_sheet).bind(dump(job.summary));
  s.bind(job.created_unix_ms).bind(job.updated_unix_ms);
}

std::expected<nlohmann::json, StoreError> parse_json(const std::string& text, std::string_view field,
                                                     const std::string& job_id) {
  auto value = nlohmann::json::parse(text, nullptr, false);
  if (value.is_discarded()) return Fail(StoreError{fmt::format("job {}: {} is not valid JSON", job_id, field)});
  return value;
}

// Columns as in kSelectJob; sheets are loaded separately.
std::expected<JobRecord, StoreError> read_job(const Statement& s) {
  JobRecord job;
  job.id = s.text(0);
  const std::string state = s.text(1);
  auto parsed = job_state_from_string(state);
  if (!parsed) return Fail(StoreError{fmt::format("job {} has an unknown state '{}'", job.id, state)});
  job.state = *parsed;
  job.model_path = s.text(2);
  job.name = s.text(3);
  auto settings = parse_json(s.text(4), "plan_settings", job.id);
  if (!settings) return Fail(settings.error());
  job.plan_settings = std::move(*settings);
  job.artefact_dir = s.text(5);
  job.error = s.text(6);
  job.current_sheet = static_cast<int>(s.integer(7));
  auto summary = parse_json(s.text(8), "summary", job.id);
  if (!summary) return Fail(summary.error());
  job.summary = std::move(*summary);
  job.created_unix_ms = s.integer(9);
  job.updated_unix_ms = s.integer(10);
  return job;
}

std::expected<void, StoreError> load_sheets(Connection& db, JobRecord& job) {
  auto s = db.statement(kSelectSheets, "read sheets");
  if (!s) return Fail(s.error());
  s->bind(job.id);
  for (;;) {
    auto row = s->step();
    if (!row) return Fail(row.error());
    if (!*row) return {};
    SheetRecord sheet;
    sheet.index = static_cast<int>(s->integer(0));
    sheet.program_path = s->text(1);
    sheet.svg_path = s->text(2);
    sheet.material = s->text(3);
    sheet.thickness_mm = s->real(4);
    sheet.lines_total = static_cast<std::size_t>(s->integer(5));
    const std::string state = s->text(6);
    auto parsed = sheet_state_from_string(state);
    if (!parsed)
      return Fail(StoreError{fmt::format("sheet {} of job {} has an unknown state '{}'", sheet.index, job.id, state)});
    sheet.state = *parsed;
    sheet.last_acked_line = static_cast<std::size_t>(s->integer(7));
    sheet.first_unfinished_line = static_cast<std::size_t>(s->integer(8));
    sheet.contour = static_cast<int>(s->integer(9));
    if (!s->is_null(10)) sheet.executed_base = static_cast<std::uint64_t>(s->integer(10));
    sheet.attempt_first_line = static_cast<std::size_t>(s->integer(11));
    sheet.attempt_preamble_lines = static_cast<std::size_t>(s->integer(12));
    sheet.cut_seconds = s->real(13);
    job.sheets.push_back(std::move(sheet));
  }
}

std::expected<void, StoreError> insert_sheets(Connection& db, const JobRecord& job) {
  for (const SheetRecord& sheet : job.sheets) {
    auto s = db.statement(kInsertSheet, "insert a sheet");
    if (!s) return Fail(s.error());
    s->bind(job.id).bind(sheet.index).bind(sheet.program_path).bind(sheet.svg_path).bind(sheet.material);
    s->bind(sheet.thickness_mm).bind(sheet.lines_total).bind(to_string(sheet.state)).bind(sheet.last_acked_line);
    s->bind(sheet.first_unfinished_line).bind(sheet.contour).bind(sheet.executed_base);
    s->bind(sheet.attempt_first_line).bind(sheet.attempt_preamble_lines).bind(sheet.cut_seconds);
    if (auto done = s->run(); !done) return done;
  }
  return {};
}

std::expected<void, StoreError> insert_event(Connection& db, const JobEvent& event) {
  auto s = db.statement(kInsertEvent, "insert an event");
  if (!s) return Fail(s.error());
  s->bind(event.job_id).bind(event.t_unix_ms).bind(event.kind).bind(dump(event.data));
  return s->run();
}

// What the operator reads on an interrupted job.
std::string interruption_message(JobState was, int sheet, std::optional<std::size_t> acked,
                                 const std::string& old_error) {
  if (was == JobState::sheet_done)
    return fmt::format("the daemon stopped after sheet {} was done, before the next one", sheet);
  std::string where = acked ? fmt::format("last acknowledged line {} of sheet {}", *acked, sheet)
                            : fmt::format("sheet {} has no record", sheet);
  std::string text = fmt::format("the daemon stopped while this job was {} ({})", to_string(was), where);
  if (was == JobState::paused && !old_error.empty()) text += fmt::format("; it had been paused: {}", old_error);
  return text;
}

}  // namespace

struct JobStore::Impl {
  explicit Impl(const std::filesystem::path& path) : db(path) {}
  Connection db;
  std::mutex mutex;
};

JobStore::JobStore(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
JobStore::~JobStore() = default;

std::expected<std::unique_ptr<JobStore>, StoreError> JobStore::open(const std::filesystem::path& db_path) {
  auto impl = std::make_unique<Impl>(db_path);
  if (auto opened = impl->db.open(5000); !opened)
    return Fail(StoreError{fmt::format("{}: open: {}", db_path.string(), opened.error().message)});
  if (auto prepared = prepare_database(impl->db); !prepared) return Fail(prepared.error());
  return std::unique_ptr<JobStore>(new JobStore(std::move(impl)));
}

std::expected<void, StoreError> JobStore::check_file() const {
  std::lock_guard lock(impl_->mutex);
  if (auto same = impl_->db.still_the_file(); !same)
    return Fail(StoreError{fmt::format("{}: {}", impl_->db.path().string(), same.error().message)});
  return {};
}

std::expected<void, StoreError> JobStore::insert_job(const JobRecord& job) {
  std::lock_guard lock(impl_->mutex);
  Connection& db = impl_->db;
  return db.transaction(fmt::format("insert job {}", job.id), Access::write, [&]() -> std::expected<void, StoreError> {
    auto s = db.statement(kInsertJob, "insert the job");
    if (!s) return Fail(s.error());
    bind_job(*s, job);
    if (auto done = s->run(); !done) return done;
    return insert_sheets(db, job);
  });
}

std::expected<void, StoreError> JobStore::update_job(const JobRecord& job) {
  std::lock_guard lock(impl_->mutex);
  Connection& db = impl_->db;
  return db.transaction(fmt::format("update job {}", job.id), Access::write, [&]() -> std::expected<void, StoreError> {
    auto s = db.statement(kUpdateJob, "update the job");
    if (!s) return Fail(s.error());
    bind_job(*s, job);
    if (auto done = db.run_one(*s, "no such job"); !done) return done;
    auto cleared = db.statement("DELETE FROM sheets WHERE job_id = ?1", "delete the old sheets");
    if (!cleared) return Fail(cleared.error());
    if (auto done = cleared->bind(job.id).run(); !done) return done;
    return insert_sheets(db, job);
  });
}

std::expected<void, StoreError> JobStore::update_sheet(const std::string& job_id, const SheetRecord& sheet) {
  std::lock_guard lock(impl_->mutex);
  Connection& db = impl_->db;
  return db.transaction(fmt::format("update sheet {} of job {}", sheet.index, job_id), Access::write,
                        [&]() -> std::expected<void, StoreError> {
                          auto s = db.statement(kUpdateSheetProgress, "update the sheet");
                          if (!s) return Fail(s.error());
                          s->bind(job_id).bind(sheet.index).bind(to_string(sheet.state)).bind(sheet.last_acked_line);
                          s->bind(sheet.first_unfinished_line).bind(sheet.contour).bind(sheet.executed_base);
                          s->bind(sheet.attempt_first_line).bind(sheet.attempt_preamble_lines).bind(sheet.cut_seconds);
                          return db.run_one(*s, "no such sheet");
                        });
}

std::expected<std::optional<JobRecord>, StoreError> JobStore::get_job(const std::string& id) const {
  std::lock_guard lock(impl_->mutex);
  Connection& db = impl_->db;
  using Result = std::expected<std::optional<JobRecord>, StoreError>;
  return db.transaction(fmt::format("read job {}", id), Access::read, [&]() -> Result {
    std::optional<JobRecord> job;
    {
      auto s = db.statement(kSelectJob, "read the job");
      if (!s) return Fail(s.error());
      s->bind(id);
      auto row = s->step();
      if (!row) return Fail(row.error());
      if (!*row) return std::optional<JobRecord>();
      auto read = read_job(*s);
      if (!read) return Fail(read.error());
      job = std::move(*read);
    }
    if (auto sheets = load_sheets(db, *job); !sheets) return Fail(sheets.error());
    return job;
  });
}

std::expected<std::vector<JobRecord>, StoreError> JobStore::list_jobs() const {
  std::lock_guard lock(impl_->mutex);
  Connection& db = impl_->db;
  using Result = std::expected<std::vector<JobRecord>, StoreError>;
  return db.transaction("list jobs", Access::read, [&]() -> Result {
    std::vector<JobRecord> jobs;
    {
      auto s = db.statement(kSelectJobs, "read the jobs");
      if (!s) return Fail(s.error());
      for (;;) {
        auto row = s->step();
        if (!row) return Fail(row.error());
        if (!*row) break;
        auto job = read_job(*s);
        if (!job) return Fail(job.error());
        jobs.push_back(std::move(*job));
      }
    }
    for (JobRecord& job : jobs)
      if (auto sheets = load_sheets(db, job); !sheets) return Fail(sheets.error());
    return jobs;
  });
}

std::expected<void, StoreError> JobStore::add_event(const JobEvent& event) {
  std::lock_guard lock(impl_->mutex);
  Connection& db = impl_->db;
  return db.transaction(fmt::format("add a {} event to job {}", event.kind, event.job_id), Access::write,
                        [&] { return insert_event(db, event); });
}

std::expected<std::vector<JobEvent>, StoreError> JobStore::events(const std::string& job_id) const {
  std::lock_guard lock(impl_->mutex);
  Connection& db = impl_->db;
  using Result = std::expected<std::vector<JobEvent>, StoreError>;
  return db.transaction(fmt::format("read the events of job {}", job_id), Access::read, [&]() -> Result {
    auto s = db.statement("SELECT t_unix_ms, kind, data FROM events WHERE job_id = ?1 ORDER BY id", "read events");
    if (!s) return Fail(s.error());
    s->bind(job_id);
    std::vector<JobEvent> events;
    for (;;) {
      auto row = s->step();
      if (!row) return Fail(row.error());
      if (!*row) return events;
      auto data = parse_json(s->text(2), "an event's data", job_id);
      if (!data) return Fail(data.error());
      events.push_back(JobEvent{job_id, s->integer(0), s->text(1), std::move(*data)});
    }
  });
}

std::expected<std::vector<std::string>, StoreError> JobStore::recover_after_restart() {
  std::lock_guard lock(impl_->mutex);
  Connection& db = impl_->db;
  using Result = std::expected<std::vector<std::string>, StoreError>;
  return db.transaction("recover after a restart", Access::write, [&]() -> Result {
    struct Found {
      std::string id;
      JobState state;
      int sheet;
      std::string error;
    };
    std::vector<Found> found;
    {  // All read first: the updates below must not run under an open cursor on jobs.
      auto s = db.statement("SELECT id, state, current_sheet, error FROM jobs ORDER BY created_unix_ms, id",
                            "read the job states");
      if (!s) return Fail(s.error());
      for (;;) {
        auto row = s->step();
        if (!row) return Fail(row.error());
        if (!*row) break;
        const std::string state = s->text(1);
        auto parsed = job_state_from_string(state);
        if (!parsed) return Fail(StoreError{fmt::format("job {} has an unknown state '{}'", s->text(0), state)});
        found.push_back({s->text(0), *parsed, static_cast<int>(s->integer(2)), s->text(3)});
      }
    }
    const std::int64_t now = now_unix_ms();
    std::vector<std::string> changed;
    for (const Found& job : found) {
      JobState to = JobState::interrupted;
      std::string error = job.error;
      if (job.state == JobState::planning) {
        to = JobState::queued;  // planned again from the start; nothing reached the machine
      } else if (job.state == JobState::cutting || job.state == JobState::paused ||
                 job.state == JobState::sheet_done) {
        std::optional<std::size_t> acked;
        {
          auto s = db.statement("SELECT last_acked_line FROM sheets WHERE job_id = ?1 AND idx = ?2",
                                "read the current sheet");
          if (!s) return Fail(s.error());
          s->bind(job.id).bind(job.sheet);
          auto row = s->step();
          if (!row) return Fail(row.error());
          if (*row) acked = static_cast<std::size_t>(s->integer(0));
        }
        error = interruption_message(job.state, job.sheet, acked, job.error);
        auto s = db.statement("UPDATE sheets SET state = ?1 WHERE job_id = ?2 AND state IN (?3, ?4)",
                              "interrupt the sheet");
        if (!s) return Fail(s.error());
        s->bind(to_string(SheetState::interrupted)).bind(job.id);
        s->bind(to_string(SheetState::cutting)).bind(to_string(SheetState::paused));
        if (auto done = s->run(); !done) return Fail(done.error());
      } else {
        continue;
      }
      {
        auto s = db.statement("UPDATE jobs SET state = ?2, error = ?3, updated_unix_ms = ?4 WHERE id = ?1",
                              "change the job's state");
        if (!s) return Fail(s.error());
        s->bind(job.id).bind(to_string(to)).bind(error).bind(now);
        if (auto done = db.run_one(*s, "the job vanished"); !done) return Fail(done.error());
      }
      const nlohmann::json data{{"from", to_string(job.state)}, {"to", to_string(to)}, {"reason", "restart"}};
      if (auto done = insert_event(db, JobEvent{job.id, now, "state", data}); !done) return Fail(done.error());
      changed.push_back(job.id);
    }
    return changed;
  });
}

}  // namespace lamina::daemon
