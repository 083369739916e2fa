#include "plan_process.hpp"

#include <fcntl.h>
#include <pthread.h>
#include <signal.h>
#include <sys/resource.h>
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

// A planner killed by a signal: say which limit it ran into when that is what happened.
std::string died_message(int signal, const PlanLimits& limits, const std::filesystem::path& log) {
  std::string why;
  if (signal == SIGXCPU || (signal == SIGKILL && limits.cpu_s > 0))
    why = fmt::format(" (its CPU-time limit is {} s)", limits.cpu_s);
  if ((signal == SIGSEGV || signal == SIGABRT || signal == SIGKILL) && limits.memory_bytes > 0)
    why += fmt::format(" (its memory limit is {} MiB: [planner] memory_limit_mb)", limits.memory_bytes >> 20);
  return fmt::format("the planner died (signal {}{}): {}", signal, why, tail_of_log(log));
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

// After fork, in the child: only async-signal-safe calls (no allocation, no locks) until exec.
// A limit the kernel refuses is written to the log and the planner runs without it.
[[noreturn]] void exec_child(char* const* argv, int log_fd, int progress_fd, const PlanLimits& limits) {
  auto note = [log_fd](const char* what) {
    (void)!::write(log_fd, what, std::strlen(what));
  };
  // Every signal is blocked here (spawn_limited): laminad's handlers are still installed, and
  // Asio's writes to laminad's own pipe — a cancel's SIGTERM arriving now used to make laminad
  // itself shut down. Defaults first, then nothing blocked: a pending SIGTERM then ends the child.
  struct sigaction default_action {};
  default_action.sa_handler = SIG_DFL;
  for (int sig = 1; sig < NSIG; ++sig) ::sigaction(sig, &default_action, nullptr);
  sigset_t none;
  ::sigemptyset(&none);
  ::sigprocmask(SIG_SETMASK, &none, nullptr);
  if (limits.memory_bytes > 0) {
    const rlimit as{static_cast<rlim_t>(limits.memory_bytes), static_cast<rlim_t>(limits.memory_bytes)};
    if (::setrlimit(RLIMIT_AS, &as) != 0) note("warning: the planner's memory limit was refused\n");
  }
  if (limits.cpu_s > 0) {
    // The soft limit sends SIGXCPU, the hard one (a second later) SIGKILL.
    const rlimit cpu{static_cast<rlim_t>(limits.cpu_s), static_cast<rlim_t>(limits.cpu_s) + 1};
    if (::setrlimit(RLIMIT_CPU, &cpu) != 0) note("warning: the planner's CPU limit was refused\n");
  }
  if (limits.nice > 0 && ::setpriority(PRIO_PROCESS, 0, limits.nice) != 0) note("warning: nice was refused\n");
  // Under memory pressure the kernel kills the planner, never laminad cutting beside it.
  if (const int adj = ::open("/proc/self/oom_score_adj", O_WRONLY | O_CLOEXEC); adj >= 0) {
    (void)!::write(adj, "1000", 4);
    ::close(adj);
  }
  // dup2 onto itself keeps O_CLOEXEC: the pipe that already is descriptor 3 must lose it here.
  if (progress_fd == kProgressFd) ::fcntl(progress_fd, F_SETFD, 0);
  const int devnull = ::open("/dev/null", O_RDONLY);
  if (devnull < 0 || ::dup2(devnull, STDIN_FILENO) < 0 || ::dup2(log_fd, STDOUT_FILENO) < 0 ||
      ::dup2(log_fd, STDERR_FILENO) < 0 || (progress_fd != kProgressFd && ::dup2(progress_fd, kProgressFd) < 0))
    ::_exit(126);
  ::execv(argv[0], argv);
  note("error: cannot run the planner (exec failed)\n");
  ::_exit(127);
}

// fork + limits + exec (posix_spawn cannot set rlimits); -1 and errno when fork fails.
pid_t spawn_limited(std::vector<char*>& argv, int log_fd, int progress_fd, const PlanLimits& limits) {
  sigset_t all, before;
  ::sigfillset(&all);
  ::pthread_sigmask(SIG_SETMASK, &all, &before);
  const pid_t pid = ::fork();
  if (pid == 0) exec_child(argv.data(), log_fd, progress_fd, limits);
  const int fork_errno = errno;
  ::pthread_sigmask(SIG_SETMASK, &before, nullptr);
  errno = fork_errno;
  return pid;
}

// The planner's report.json, read with the planner's own schema (lamina/core/plan_report.hpp):
// a planner of another version, or a bug on one side, fails the job with the key that differs —
// never a sheet 0.
std::expected<PlanReport, PlanProcessError> read_report(const std::filesystem::path& out_dir) {
  std::ifstream in(out_dir / "report.json", std::ios::binary);
  if (!in) return std::unexpected(PlanProcessError{false, "the planner wrote no report.json"});
  const std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  auto report = parse_plan_report(text);
  if (!report)
    return std::unexpected(PlanProcessError{false, fmt::format("the planner's report does not match this laminad: {}",
                                                               report.error().message)});
  return std::move(*report);
}

}  // namespace

std::expected<PlanReport, PlanProcessError> run_plan_process(const PlanProcessRequest& r,
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
                                "--progress-fd", std::to_string(kProgressFd),
                                // A client named the file: its bytes stay out of job.error and the log.
                                "--no-quote-input"};
  args.insert(args.end(), r.flags.begin(), r.flags.end());
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);

  const int log_fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0640);
  if (log_fd < 0) return std::unexpected(PlanProcessError{false, fmt::format("{}: {}", log.string(), std::strerror(errno))});
  const pid_t pid = spawn_limited(argv, log_fd, progress_pipe[1], r.limits);
  const int spawn_errno = errno;
  ::close(log_fd);
  if (pid < 0)
    return std::unexpected(PlanProcessError{false, fmt::format("cannot start {}: {}", args[0], std::strerror(spawn_errno))});

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
  if (WIFSIGNALED(status)) return std::unexpected(PlanProcessError{false, died_message(WTERMSIG(status), r.limits, log)});
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0)
    return std::unexpected(PlanProcessError{false, fmt::format("planning failed: {}", tail_of_log(log))});

  return read_report(r.out_dir);
}

}  // namespace lamina::daemon
