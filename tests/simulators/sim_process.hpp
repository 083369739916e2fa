#pragma once
// Test harness: start the lamina-sim program as a separate process (it is a peer, not a
// library here), learn its ports from the ready line, and talk to it as clients do — termios
// on the PTY, plain sockets on TCP, text on the control socket.
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <termios.h>
#include <unistd.h>
#include <arpa/inet.h>
#include <netinet/in.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

extern char** environ;

namespace lamina::sim::testing {

// A link the simulator closes must show up as a failed write, not kill the test with SIGPIPE.
inline const bool kSigpipeIgnored = (std::signal(SIGPIPE, SIG_IGN), true);

inline double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// A scratch folder per test, removed afterwards.
class TempDir {
 public:
  TempDir() {
    std::string pattern = (std::filesystem::temp_directory_path() / "lamina-sim-XXXXXX").string();
    if (!::mkdtemp(pattern.data())) throw std::runtime_error("mkdtemp failed");
    path_ = pattern;
  }
  ~TempDir() {
    // LAMINA_KEEP_TEST_DIRS=1 keeps the logs of a failing run for a look afterwards.
    if (const char* keep = std::getenv("LAMINA_KEEP_TEST_DIRS"); keep && std::string(keep) == "1") return;
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  std::string file(const std::string& name) const { return (path_ / name).string(); }

 private:
  std::filesystem::path path_;
};

// Every simulator a test starts runs paced to the host (--pace-to-host, host_pacer.hpp) unless the
// test says --no-pace-to-host: a test that streams to a compressed machine must not depend on the
// CI machine keeping its host scheduled (a drip feed at 2x starved under load, 2026-12-06). At a
// time scale of 1 pacing changes nothing; the tests of starvation itself say --no-pace-to-host.
inline std::vector<std::string> paced_by_default(std::vector<std::string> args) {
  if (std::find(args.begin(), args.end(), "--no-pace-to-host") == args.end() &&
      std::find(args.begin(), args.end(), "--pace-to-host") == args.end())
    args.push_back("--pace-to-host");
  return args;
}

class SimProcess {
 public:
  explicit SimProcess(std::vector<std::string> args) {
    args = paced_by_default(std::move(args));
    int out[2];
    if (::pipe(out) != 0) throw std::runtime_error("pipe failed");
    std::vector<char*> argv;
    args.insert(args.begin(), LAMINA_SIM);
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_adddup2(&actions, out[1], 1);
    posix_spawn_file_actions_addclose(&actions, out[0]);
    if (posix_spawn(&pid_, LAMINA_SIM, &actions, nullptr, argv.data(), environ) != 0)
      throw std::runtime_error("cannot start lamina-sim");
    posix_spawn_file_actions_destroy(&actions);
    ::close(out[1]);
    stdout_fd_ = out[0];
    const std::string line = read_stdout_line(15.0);
    if (line.empty()) throw std::runtime_error("lamina-sim printed no ready line");
    ready_ = nlohmann::json::parse(line);
  }
  ~SimProcess() { stop(); }

  const nlohmann::json& ready() const { return ready_; }
  int modbus_port() const { return ready_.value("modbus_port", 0); }
  int tcp_port() const { return ready_.value("tcp_port", 0); }
  int control_port() const { return ready_.value("control_port", 0); }

  // SIGTERM and wait; returns the exit status (or -1 when it had to be killed).
  int stop() {
    if (pid_ <= 0) return 0;
    ::kill(pid_, SIGTERM);
    int status = 0;
    for (int i = 0; i < 500; ++i) {
      if (::waitpid(pid_, &status, WNOHANG) == pid_) {
        pid_ = -1;
        ::close(stdout_fd_);
        return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    ::kill(pid_, SIGKILL);
    ::waitpid(pid_, &status, 0);
    pid_ = -1;
    ::close(stdout_fd_);
    return -1;
  }

 private:
  std::string read_stdout_line(double timeout_s) {
    std::string line;
    const auto t0 = std::chrono::steady_clock::now();
    while (seconds_since(t0) < timeout_s) {
      pollfd p{stdout_fd_, POLLIN, 0};
      if (::poll(&p, 1, 100) <= 0) continue;
      char c;
      if (::read(stdout_fd_, &c, 1) != 1) break;
      if (c == '\n') return line;
      line += c;
    }
    return line;
  }

  pid_t pid_ = -1;
  int stdout_fd_ = -1;
  nlohmann::json ready_;
};

// lamina-sim on a PTY in a fresh folder, with its execution log and control socket; `first`
// goes before the common flags (e.g. a personality), `extra` after them.
struct LoggedSim {
  TempDir dir;
  std::string link = dir.file("cnc");
  std::string log = dir.file("exec.jsonl");
  SimProcess sim;
  explicit LoggedSim(std::vector<std::string> extra, std::vector<std::string> first = {})
      : sim([&] {
          std::vector<std::string> args = std::move(first);
          args.insert(args.end(), {"--link", link, "--log", log, "--control", "127.0.0.1:0"});
          args.insert(args.end(), extra.begin(), extra.end());
          return args;
        }()) {}
};

// A byte-stream client (PTY through termios, or TCP) with timed reads.
class StreamClient {
 public:
  static StreamClient open_pty(const std::string& link) {
    const int fd = ::open(link.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0) throw std::runtime_error("cannot open " + link);
    termios t{};
    ::tcgetattr(fd, &t);
    ::cfmakeraw(&t);
    ::cfsetspeed(&t, B115200);  // a PTY ignores the speed; the simulator paces the bytes
    ::tcsetattr(fd, TCSANOW, &t);
    return StreamClient(fd);
  }
  static StreamClient connect_tcp(int port) {
    const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    sockaddr_in addr{};
    addr.sin_family = AF_INET;
    addr.sin_port = htons(static_cast<uint16_t>(port));
    ::inet_pton(AF_INET, "127.0.0.1", &addr.sin_addr);
    if (::connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) {
      ::close(fd);
      throw std::runtime_error("cannot connect to port " + std::to_string(port));
    }
    ::fcntl(fd, F_SETFL, ::fcntl(fd, F_GETFL) | O_NONBLOCK);
    return StreamClient(fd);
  }
  StreamClient(StreamClient&& o) noexcept : fd_(o.fd_), buffer_(std::move(o.buffer_)), closed_(o.closed_) { o.fd_ = -1; }
  ~StreamClient() {
    if (fd_ >= 0) ::close(fd_);
  }

  // False when the link is gone (an unplugged PTY answers EIO, a dropped socket EPIPE).
  bool send(const std::string& bytes) {
    std::size_t done = 0;
    while (done < bytes.size() && !closed_) {
      const ssize_t n = ::write(fd_, bytes.data() + done, bytes.size() - done);
      if (n > 0) {
        done += static_cast<std::size_t>(n);
      } else if (n < 0 && errno == EAGAIN) {
        pollfd p{fd_, POLLOUT, 0};
        ::poll(&p, 1, 10);
      } else {
        closed_ = true;
      }
    }
    return !closed_;
  }
  // Read whatever arrives within `wait_s` (returns early when `done(buffer)` is true).
  bool read_until(const std::function<bool(const std::string&)>& done, double wait_s) {
    const auto t0 = std::chrono::steady_clock::now();
    for (bool first = true; !done(buffer_); first = false) {
      const double left = wait_s - seconds_since(t0);
      if ((left <= 0 && !first) || closed_) return done(buffer_);
      pollfd p{fd_, POLLIN, 0};  // always look once, even with no time to wait
      if (::poll(&p, 1, std::max(0, static_cast<int>(left * 1000))) <= 0) continue;
      char chunk[4096];
      const ssize_t n = ::read(fd_, chunk, sizeof chunk);
      if (n > 0) buffer_.append(chunk, static_cast<std::size_t>(n));
      else if (n == 0 || (errno != EAGAIN && errno != EINTR)) closed_ = true;
    }
    return true;
  }
  bool wait_for(const std::string& text, double wait_s) {
    return read_until([&](const std::string& b) { return b.find(text) != std::string::npos; }, wait_s);
  }
  // Count occurrences of `text` in what was read so far.
  std::size_t count(const std::string& text) const {
    std::size_t n = 0;
    for (auto pos = buffer_.find(text); pos != std::string::npos; pos = buffer_.find(text, pos + text.size())) ++n;
    return n;
  }
  std::string& buffer() { return buffer_; }
  bool closed() const { return closed_; }
  int fd() const { return fd_; }

 private:
  explicit StreamClient(int fd) : fd_(fd) {}
  int fd_;
  std::string buffer_;
  bool closed_ = false;
};

// A native-USB grblHAL (lamina-sim's default --on-open quiet) says nothing when a host opens
// its port: ask for a status report (a real-time byte, no line, no ok) to know it is there.
// The answer is dropped from the buffer.
inline bool wait_controller(StreamClient& c, double wait_s = 3.0) {
  c.send("?");
  const bool there = c.wait_for(">\r\n", wait_s);
  c.buffer().clear();
  return there;
}

// Run lamina-sim to its exit (for start-up errors): exit status and everything it printed.
struct SimExit {
  int status = -1;
  std::string output;
};
inline SimExit run_sim_to_exit(const std::string& args) {
  SimExit r;
  const std::string command = std::string("'") + LAMINA_SIM + "' " + args + " 2>&1";
  FILE* pipe = ::popen(command.c_str(), "r");
  if (!pipe) return r;
  char chunk[512];
  while (std::fgets(chunk, sizeof chunk, pipe)) r.output += chunk;
  const int status = ::pclose(pipe);
  r.status = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

// One command, one reply line on the simulator's control socket.
inline std::string control(int port, const std::string& command) {
  StreamClient c = StreamClient::connect_tcp(port);
  c.send(command + "\n");
  c.wait_for("\n", 5.0);
  std::string reply = c.buffer();
  if (!reply.empty() && reply.back() == '\n') reply.pop_back();
  return reply;
}
inline nlohmann::json control_status(int port) { return nlohmann::json::parse(control(port, "status")); }

inline std::vector<nlohmann::json> read_log(const std::string& path) {
  std::vector<nlohmann::json> out;
  std::ifstream in(path);
  for (std::string line; std::getline(in, line);)
    if (!line.empty()) out.push_back(nlohmann::json::parse(line));
  return out;
}
inline std::vector<nlohmann::json> executed_blocks(const std::vector<nlohmann::json>& log) {
  std::vector<nlohmann::json> out;
  for (const auto& r : log)
    if (r.contains("seq") && !r.contains("event")) out.push_back(r);
  return out;
}

// Wait (polling the control socket) until `ready(status)` holds.
inline bool wait_status(int port, const std::function<bool(const nlohmann::json&)>& ready, double wait_s) {
  const auto t0 = std::chrono::steady_clock::now();
  while (seconds_since(t0) < wait_s) {
    if (ready(control_status(port))) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return false;
}

}  // namespace lamina::sim::testing
