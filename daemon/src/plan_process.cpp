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

// The descriptor the planner writes its phases to, as the child sees it.
constexpr int kProgressFd = 3;

// Complete lines from the progress pipe (non-blocking); a partial line waits for the rest.
void drain_progress(int fd, std::string& pending, const PlanProgressCallback& on_progress) {
  char buf[1024];
  while (true) {
    const ssize_t n = ::read(fd, buf, sizeof buf);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    pending.append(buf, static_cast<std::size_t>(n));
  }
  for (std::size_t eol; (eol = pending.find('\n')) != std::string::npos;) {
    const std::string line = pending.substr(0, eol);
    pending.erase(0, eol + 1);
    auto j = nlohmann::json::parse(line, nullptr, false);
    if (!j.is_discarded() && j.is_object() && on_progress) on_progress(j);
  }
  if (pending.size() > 4096) pending.clear();  // not ours to keep: no line is that long
}

}  // namespace

std::expected<nlohmann::json, PlanProcessError> run_plan_process(const PlanProcessRequest& r,
                                                                 const std::atomic<bool>& cancel,
                                                                 const PlanProgressCallback& on_progress) {
  std::error_code ec;
  std::filesystem::create_directories(r.out_dir, ec);
  if (ec) return std::unexpected(PlanProcessError{false, fmt::format("{}: {}", r.out_dir.string(), ec.message())});
  const std::filesystem::path log = r.out_dir / "plan.log";

  int progress_pipe[2] = {-1, -1};
  if (::pipe2(progress_pipe, O_CLOEXEC | O_NONBLOCK) != 0)
    return std::unexpected(PlanProcessError{false, fmt::format("cannot make the progress pipe: {}", std::strerror(errno))});
  // The child's end blocks (a planner must not lose a line to EAGAIN); ours does not.
  ::fcntl(progress_pipe[1], F_SETFL, ::fcntl(progress_pipe[1], F_GETFL) & ~O_NONBLOCK);
  struct Closer {
    int* fds;
    ~Closer() {
      for (int i = 0; i < 2; ++i)
        if (fds[i] >= 0) ::close(fds[i]);
    }
  } closer{progress_pipe};

  std::vector<std::string> args{r.lamina.string(), "plan", r.model.string(), "--out", r.out_dir.string(), "--json",
                                "--progress-fd", std::to_string(kProgressFd)};
  args.insert(args.end(), r.flags.begin(), r.flags.end());
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);

  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0640);
  posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
  posix_spawn_file_actions_adddup2(&actions, progress_pipe[1], kProgressFd);  // dup2 drops O_CLOEXEC
  pid_t pid = -1;
  const int rc = ::posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (rc != 0)
    return std::unexpected(PlanProcessError{false, fmt::format("cannot start {}: {}", args[0], std::strerror(rc))});

  ::close(progress_pipe[1]);  // the child holds the write end now
  progress_pipe[1] = -1;
  std::string pending;

  const auto started = Clock::now();
  std::optional<Clock::time_point> term_sent;
  bool cancelled = false, timed_out = false;
  int status = 0;
  while (true) {
    drain_progress(progress_pipe[0], pending, on_progress);
    const pid_t done = ::waitpid(pid, &status, WNOHANG);
    if (done == pid) {
      drain_progress(progress_pipe[0], pending, on_progress);  // its last lines
      break;
    }
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
