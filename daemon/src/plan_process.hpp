#pragma once
// Planning runs `lamina plan` as a child process, not in the daemon: a hostile or huge mesh can
// exhaust memory or crash the planner without touching the daemon, a cancel is a signal, and
// the memory of a plan is returned to the system when it ends. The child writes its programs,
// drawings, stack.stl and report.json into the job's folder; its output goes to plan.log there.
#include <atomic>
#include <cstdint>
#include <expected>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "lamina/core/plan_report.hpp"

namespace lamina::daemon {

// Limits of the child, set before it runs (setrlimit, nice): a huge or hostile model makes its
// own job fail, never the cut beside it. Its oom_score_adj is 1000, so the kernel, short of
// memory, kills the planner first.
struct PlanLimits {
  std::uint64_t memory_bytes = 0;     // RLIMIT_AS; 0: none
  double cpu_s = 0;                   // RLIMIT_CPU; 0: none
  int nice = 0;
};

struct PlanProcessRequest {
  std::filesystem::path lamina;       // the `lamina` program
  std::filesystem::path model;
  std::filesystem::path out_dir;
  std::vector<std::string> flags;     // from plan_args_from_settings, plus machine/materials
  double timeout_s = 3600;
  PlanLimits limits;
};

struct PlanProcessError {
  bool cancelled = false;
  std::string message;  // the planner's last error lines, or what failed around it
};

// One phase line of the planner (`lamina plan --progress-fd`): {phase, step, steps}.
using PlanProgressCallback = std::function<void(const nlohmann::json&)>;

// Blocking (a worker thread). Returns report.json as read by the planner's schema (a file that
// does not match it is an error naming the key). `cancel` is polled every 50 ms:
// SIGTERM, then SIGKILL 2 s later. `on_progress` (optional) runs on this thread as each phase
// starts; the planner writes them to a pipe, a line that is not JSON is skipped.
std::expected<PlanReport, PlanProcessError> run_plan_process(const PlanProcessRequest& request,
                                                                 const std::atomic<bool>& cancel,
                                                                 const PlanProgressCallback& on_progress = {});

}  // namespace lamina::daemon
