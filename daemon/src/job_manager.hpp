#pragma once
// The jobs of the cell and their state machine (docs/api.md "Job states"). Called from the RPC
// handlers — on the RPC worker thread, the four inline methods on the io thread — and every
// public method returns quickly; it plans on worker threads (lamina plan as a child process)
// and cuts on one cutting thread through the MachineSession.
// Every state change is written to the JobStore before it is announced.
#include <atomic>
#include <condition_variable>
#include <deque>
#include <expected>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "lamina/core/plan_report.hpp"
#include "lamina/daemon/daemon_config.hpp"
#include "lamina/daemon/job_model.hpp"
#include "lamina/daemon/job_store.hpp"
#include "lamina/daemon/roles.hpp"
#include "job_error.hpp"
#include "lamina/drivers/cut_job.hpp"
#include "machine_session.hpp"

namespace lamina::daemon {

// Who asked for an action, for the job's events: a console login, "unix pid 1 uid 0", "tcp".
struct Actor {
  std::string user;
  Role role = Role::engineer;
};

struct SubmitRequest {
  std::string model_path;             // as the client named it (inside [jobs] roots), or the upload's file
  std::string name;                   // for people; default: the file name
  nlohmann::json settings = nlohmann::json::object();  // plan settings (plan_settings.hpp)
  bool move_into_job = false;         // an upload: the file moves into the job's folder
  Actor by;
};

class JobManager {
 public:
  // notify(method, params): notify_job_progress / notify_machine_status to subscribed clients.
  using Notifier = std::function<void(const std::string& method, const nlohmann::json& params)>;

  JobManager(const DaemonConfig& config, JobStore& store, MachineSession& machine, Notifier notify);
  ~JobManager();  // shutdown() if not done
  JobManager(const JobManager&) = delete;
  JobManager& operator=(const JobManager&) = delete;

  // Loads the jobs (after JobStore::recover_after_restart), starts the planner workers.
  std::expected<void, JobError> start();
  // SIGTERM: stop planning, stop the cut safely (its job becomes interrupted), wait for threads.
  void shutdown(const std::string& why);

  std::expected<JobRecord, JobError> submit(SubmitRequest request);
  std::vector<JobRecord> list() const;
  std::expected<JobRecord, JobError> get(const std::string& id) const;
  std::expected<std::vector<JobEvent>, JobError> events(const std::string& id) const;  // oldest first
  // The operator's and engineer's actions: each is an "action" event of its job, with who.
  std::expected<JobRecord, JobError> cancel(const std::string& id, const Actor& by);
  std::expected<JobRecord, JobError> confirm_sheet(const std::string& id, int sheet, const Actor& by);
  std::expected<JobRecord, JobError> resume(const std::string& id, const Actor& by);  // paused or interrupted

  nlohmann::json machine_status();  // checks the database file too
  std::expected<nlohmann::json, JobError> hold(const Actor& by);
  std::expected<nlohmann::json, JobError> resume_motion(const Actor& by);
  std::expected<nlohmann::json, JobError> abort(const std::string& why, const Actor& by);

  std::string status_line() const;  // for sd_notify STATUS=

 private:
  enum class CutStart { fresh, resume_stopped, resume_interrupted };
  enum class PauseKind { none, hold, stopped };

  // --- under mutex_ ---
  std::expected<void, JobError> set_state(JobRecord& job, JobState to, const std::string& why = {});
  void store_failed(const std::string& message);     // latches the fault, stops the cut
  std::optional<JobError> store_refusal() const;      // -32014 while the store has failed
  void reload(JobRecord& job);                        // memory as the database has it
  void event(const JobRecord& job, const std::string& kind, nlohmann::json data);
  void action(const JobRecord& job, const std::string& what, const Actor& by, nlohmann::json data = nlohmann::json::object());
  void announce(const JobRecord& job);
  void assign_machine();              // the oldest planned job gets the machine when it is free
  JobRecord* find(const std::string& id);
  const JobRecord* find(const std::string& id) const;
  struct ProgramRead {
    std::string path;
    std::vector<std::string> lines;
    // Where its contours are, as the post made it (report.json), checked against `lines`.
    std::expected<drivers::ProgramMap, std::string> map = std::unexpected(std::string("not read"));
  };
  static std::vector<std::string> read_program(const std::string& path);
  ProgramRead read_current_program(const std::string& job_id) const;  // takes the lock briefly
  std::expected<void, JobError> start_cut(JobRecord& job, CutStart how, const ProgramRead& read);
  std::expected<void, JobError> stage_inputs(JobRecord& job, const SubmitRequest& r) const;  // no lock needed

  // --- threads ---
  void planner_loop();
  void plan_job(const std::string& id);
  bool take_plan(JobRecord& job, const PlanReport& report);
  void cut_sheet(std::string job_id, int sheet, CutStart how, std::vector<std::string> program,
                 std::optional<std::size_t> resume_line);
  void finish_cut(const std::string& job_id, int sheet, const drivers::CutReport& report);
  void save_progress(const std::string& job_id, int sheet, const drivers::CutReport& report);
  void machine_held(const std::string& job_id, const drivers::LinkError& why);
  std::size_t interrupted_resume_line(const SheetRecord& sheet, const std::vector<std::string>& program,
                                      std::string& note);

  DaemonConfig config_;
  JobStore& store_;
  MachineSession& machine_;
  Notifier notify_;

  mutable std::mutex mutex_;
  std::condition_variable plan_wake_;
  std::map<std::string, JobRecord> jobs_;
  std::deque<std::string> plan_queue_;
  std::map<std::string, std::shared_ptr<std::atomic<bool>>> plan_cancel_;
  std::vector<std::thread> planners_;
  bool stopping_ = false;
  std::optional<std::string> store_fault_;  // a store write failed: see store_failed

  std::string machine_job_;           // the job that owns the machine (empty: free)
  std::string cancel_after_stop_;     // cancel this job when its cut has stopped
  // The cut of machine_job_'s current sheet. Shared: hold and abort act on it outside the lock,
  // and a cut that ends meanwhile must not be destroyed under them.
  std::shared_ptr<drivers::CutJob> cut_;
  std::thread cutter_;
  bool cutting_ = false;              // cutter_ is streaming
  PauseKind pause_ = PauseKind::none;
  std::chrono::steady_clock::time_point last_saved_{}, last_announced_{};
};

}  // namespace lamina::daemon
