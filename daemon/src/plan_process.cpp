#include "plan_process.hpp"

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <fstream>
#include <optional>
#include <sstream>
#include <thread>

#include <fmt/format.h>

extern char** environ;

namespace lamina::daemon {
namespace {

using Clock = std::chrono::steady_clock;

// The planner's own error lines ("error [...]: …") are the useful part of its log.
std::string tail_of_log(const std::filesystem::path& log) {
  std::ifstream in(log);
  std::string line, errors, last;
  while (std::getline(in, line)) {
    if (line.rfind("error", 0) == 0) errors += (errors.empty() ? "" : "; ") + line;
    if (!line.empty()) last = line;
  }
  return errors.empty() ? last : errors;
}

}  // namespace

std::expected<nlohmann::json, PlanProcessError> run_plan_process(const PlanProcessRequest& r,
                                                                 const std::atomic<bool>& cancel) {
  std::error_code ec;
  std::filesystem::create_directories(r.out_dir, ec);
  if (ec) return std::unexpected(PlanProcessError{false, fmt::format("{}: {}", r.out_dir.string(), ec.message())});
  const std::filesystem::path log = r.out_dir / "plan.log";

  std::vector<std::string> args{r.lamina.string(), "plan", r.model.string(), "--out", r.out_dir.string(), "--json"};
  args.insert(args.end(), r.flags.begin(), r.flags.end());
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);

  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0640);
  posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
  pid_t pid = -1;
  const int rc = ::posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (rc != 0)
    return std::unexpected(PlanProcessError{false, fmt::format("cannot start {}: {}", args[0], std::strerror(rc))});

  const auto started = Clock::now();
  std::optional<Clock::time_point> term_sent;
  bool cancelled = false, timed_out = false;
  int status = 0;
  while (true) {
    const pid_t done = ::waitpid(pid, &status, WNOHANG);
    if (done == pid) break;
    if (done < 0 && errno != EINTR) return std::unexpected(PlanProcessError{false, "waitpid failed"});
    const auto now = Clock::now();
    if (!term_sent && (cancel.load() || std::chrono::duration<double>(now - started).count() > r.timeout_s)) {
      cancelled = cancel.load();
      timed_out = !cancelled;
      ::kill(pid, SIGTERM);
      term_sent = now;
    } else if (term_sent && now - *term_sent > std::chrono::seconds(2)) {
      ::kill(pid, SIGKILL);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  if (cancelled) return std::unexpected(PlanProcessError{true, "cancelled while planning"});
  if (timed_out) return std::unexpected(PlanProcessError{false, fmt::format("planning took longer than {} s", r.timeout_s)});
  if (WIFSIGNALED(status))
    return std::unexpected(PlanProcessError{false, fmt::format("the planner died (signal {}): {}", WTERMSIG(status), tail_of_log(log))});
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0)
    return std::unexpected(PlanProcessError{false, fmt::format("planning failed: {}", tail_of_log(log))});

  std::ifstream in(r.out_dir / "report.json");
  if (!in) return std::unexpected(PlanProcessError{false, "the planner wrote no report.json"});
  try {
    return nlohmann::json::parse(in);
  } catch (const std::exception& e) {
    return std::unexpected(PlanProcessError{false, fmt::format("report.json: {}", e.what())});
  }
}

}  // namespace lamina::daemon
