#pragma once
// Jobs, their sheets and events in SQLite (WAL) under the state directory. Thread-safe (one
// connection behind a mutex). Every write is a transaction: a kill -9 between two calls leaves
// the last committed state, never a half-written job.
#include <expected>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "lamina/daemon/job_model.hpp"

namespace lamina::daemon {

struct StoreError {
  std::string message;  // names the database file and what failed
};

class JobStore {
 public:
  // Creates the file and schema when missing (schema version checked; newer → error).
  static std::expected<std::unique_ptr<JobStore>, StoreError> open(const std::filesystem::path& db_path);
  ~JobStore();
  JobStore(const JobStore&) = delete;
  JobStore& operator=(const JobStore&) = delete;

  std::expected<void, StoreError> insert_job(const JobRecord& job);       // with its sheets
  std::expected<void, StoreError> update_job(const JobRecord& job);       // all fields, sheets replaced
  // The hot path while cutting (several times a second): one sheet's progress fields only.
  std::expected<void, StoreError> update_sheet(const std::string& job_id, const SheetRecord& sheet);
  std::expected<std::optional<JobRecord>, StoreError> get_job(const std::string& id) const;
  std::expected<std::vector<JobRecord>, StoreError> list_jobs() const;  // oldest first
  std::expected<void, StoreError> add_event(const JobEvent& event);
  std::expected<std::vector<JobEvent>, StoreError> events(const std::string& job_id) const;  // oldest first

  // At start-up, before serving: jobs left `planning` go back to `queued` (planned again);
  // `cutting`, `paused` and `sheet_done` become `interrupted` (their sheet too), with an event.
  // Returns the ids changed.
  std::expected<std::vector<std::string>, StoreError> recover_after_restart();

  // The database file is still there and the one opened (every write checks this too).
  std::expected<void, StoreError> check_file() const;

 private:
  struct Impl;
  explicit JobStore(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace lamina::daemon
