#pragma once
// laminad as the shop runs it, against lamina-sim: the simulator (CNC on a PTY, PLC on Modbus)
// and the daemon as separate processes, a config written per test, clients over the socket.
#include <signal.h>
#include <spawn.h>
#include <sys/mount.h>
#include <sys/wait.h>

#include <cerrno>
#include <cstdio>
#include <cstring>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <thread>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "lamina/daemon/rpc_client.hpp"
#include "sim_process.hpp"

extern char** environ;

namespace lamina::daemon::testing {

using sim::testing::SimProcess;
using sim::testing::TempDir;
using Json = nlohmann::json;

inline double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// The PLC's heartbeat watchdog (wall ms) for tests that kill the daemon or stand the machine
// without it and count on the PLC to close the jet and hold the CNC at once (the recovery tests,
// the fault campaign's 250 ms standstill limit).
inline constexpr int kKillWatchdogMs = 1000;
// For every other test: 5 s. The daemon beats every 0.2 s, and at 1 s a sanitized daemon on a
// loaded 2-core machine missed it once: the job paused on "PLC alarm 2 (heartbeat watchdog)
// latched" in the middle of a test about cutting sheets.
inline constexpr int kWatchdogMs = 5000;

// The simulated cell, fast: 20× time, 921600 baud (the link is not what these tests measure),
// paced to the host (--pace-to-host): real time while the daemon falls behind, so a sanitized
// daemon's pause on a loaded machine is not taken for a daemon too slow for a real one.
struct Cell {
  explicit Cell(std::vector<std::string> extra = {}, double time_scale = 20, int watchdog_ms = kWatchdogMs)
      : sim([&] {
          std::vector<std::string> args{"--link", dir.file("cnc"), "--modbus", "127.0.0.1:0", "--control", "127.0.0.1:0",
                                        "--log", dir.file("exec.jsonl"), "--pressure-ramp", "0.2", "--baud", "921600",
                                        "--time-scale", fmt::format("{}", time_scale), "--pace-to-host", "--heartbeat-timeout", std::to_string(watchdog_ms),
                                        "--machine", std::string(LAMINA_SOURCE_DIR) + "/config/sim-machine.toml"};
          args.insert(args.end(), extra.begin(), extra.end());
          return args;
        }()) {}
  TempDir dir;  // before sim: it outlives the process
  SimProcess sim;

  // `http`: the [http] section's lines (off unless a test serves the console).
  std::string config(const std::string& extra_server = "", const std::string& http = "listen = \"\"") const {
    return fmt::format(R"(state_dir = "{state}"
[server]
socket = "{sock}"
socket_group = ""
{extra}
[http]
{http}
[link]
protocol = "grbl"
port = "{cnc}"
baud = 921600
[cell]
modbus = "127.0.0.1:{modbus}"
[planner]
lamina = "{lamina}"
memory_limit_mb = {memory_mb}
[jobs]
roots = ["{examples}", "{parts}"]
)",
                       fmt::arg("state", dir.file("state")), fmt::arg("sock", dir.file("lamina.sock")),
                       fmt::arg("extra", extra_server), fmt::arg("http", http), fmt::arg("cnc", dir.file("cnc")),
                       fmt::arg("modbus", sim.modbus_port()), fmt::arg("lamina", LAMINA_CLI),
                       fmt::arg("examples", LAMINA_EXAMPLES_DIR), fmt::arg("parts", dir.file("parts")),
                       // A sanitizer build reserves terabytes of shadow address space.
                       fmt::arg("memory_mb", LAMINA_SANITIZED ? 0 : 4096));
  }
  std::string socket() const { return dir.file("lamina.sock"); }
  std::string log() const { return dir.file("exec.jsonl"); }
};

class Laminad {
 public:
  Laminad(const std::string& config_text, const std::string& dir, std::vector<std::string> env_extra = {})
      : config_path_(dir + "/lamina.toml"), log_path_(dir + "/laminad.log") {
    std::ofstream(config_path_) << config_text;
    start(env_extra);
  }
  ~Laminad() { stop(SIGTERM); }

  void start(const std::vector<std::string>& env_extra = {}) {
    std::vector<std::string> args{LAMINAD, "--config", config_path_};
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    std::vector<std::string> env_strings;
    for (char** e = environ; *e; ++e) env_strings.emplace_back(*e);
    env_strings.insert(env_strings.end(), env_extra.begin(), env_extra.end());
    std::vector<char*> envp;
    for (auto& e : env_strings) envp.push_back(e.data());
    envp.push_back(nullptr);
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, 1, log_path_.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
    posix_spawn_file_actions_adddup2(&actions, 1, 2);
    if (posix_spawn(&pid_, LAMINAD, &actions, nullptr, argv.data(), envp.data()) != 0)
      throw std::runtime_error("cannot start laminad");
    posix_spawn_file_actions_destroy(&actions);
  }

  // Signal and wait (SIGKILL after 30 s); the exit status, or -signal.
  int stop(int signal) {
    if (pid_ <= 0) return 0;
    ::kill(pid_, signal);
    int status = 0;
    const auto t0 = std::chrono::steady_clock::now();
    while (::waitpid(pid_, &status, WNOHANG) != pid_) {
      if (seconds_since(t0) > 30) {
        ::kill(pid_, SIGKILL);
        ::waitpid(pid_, &status, 0);
        break;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    pid_ = -1;
    return WIFEXITED(status) ? WEXITSTATUS(status) : -WTERMSIG(status);
  }
  bool running() {
    if (pid_ <= 0) return false;
    int status = 0;
    return ::waitpid(pid_, &status, WNOHANG) == 0;
  }
  std::string log() const {
    std::ifstream in(log_path_);
    return std::string(std::istreambuf_iterator<char>(in), {});
  }

 private:
  std::string config_path_, log_path_;
  pid_t pid_ = -1;
};

// A client once the daemon listens (it may still be starting).
inline RpcClient connect(const std::string& socket, double wait_s = 20) {
  const auto t0 = std::chrono::steady_clock::now();
  while (true) {
    auto c = RpcClient::connect_unix(socket);
    if (c) return std::move(*c);
    if (seconds_since(t0) > wait_s) throw std::runtime_error("laminad does not listen on " + socket + ": " + c.error());
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
}

inline Json call_ok(RpcClient& c, const std::string& method, Json params = Json::object()) {
  auto r = c.call(method, std::move(params), 30);
  if (!r) throw std::runtime_error(fmt::format("{}: {} ({})", method, r.error().message, r.error().code));
  return *r;
}

// Polls job.get until `ready` says so; the last answer (check its state in the test).
inline Json wait_job(RpcClient& c, const std::string& id, const std::function<bool(const Json&)>& ready, double wait_s) {
  const auto t0 = std::chrono::steady_clock::now();
  Json j;
  while (seconds_since(t0) < wait_s) {
    j = call_ok(c, "job.get", {{"job", id}});
    if (ready(j)) return j;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return j;
}
inline Json wait_state(RpcClient& c, const std::string& id, const std::string& state, double wait_s) {
  return wait_job(c, id, [&](const Json& j) { return j["state"] == state || j["state"] == "failed"; }, wait_s);
}

// The `lamina` client as an operator types it: exit status and output (stdout and stderr).
struct ClientRun {
  int exit_code = -1;
  std::string output;
};

// The client as the operator runs it, once the daemon listens (a sanitized daemon starts slowly:
// without the wait the client can race its start).
inline ClientRun run_client(const std::string& socket, const std::string& args) {
  (void)connect(socket);
  const std::string command = fmt::format("timeout -k 5 120 '{}' {} --socket '{}' 2>&1 < /dev/null", LAMINA_CLI, args, socket);
  ClientRun r;
  FILE* pipe = ::popen(command.c_str(), "r");
  char buf[4096];
  while (pipe && std::fgets(buf, sizeof buf, pipe)) r.output += buf;
  const int status = pipe ? ::pclose(pipe) : -1;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

// The program lines a sheet's file holds, as the daemon streams them (blank lines dropped).
inline std::vector<std::string> program_lines(const std::string& path) {
  std::vector<std::string> lines;
  std::ifstream in(path);
  for (std::string line; std::getline(in, line);) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (!line.empty()) lines.push_back(line);
  }
  return lines;
}

struct LogBlock {
  std::string line;
  bool completed;
};
inline std::vector<LogBlock> executed(const std::string& log) {
  std::vector<LogBlock> out;
  for (const auto& r : sim::testing::executed_blocks(sim::testing::read_log(log)))
    out.push_back({r["line"], r.value("completed", true)});
  return out;
}

// The first run is the program's prefix; the resumed run starts at the contour that was being
// cut when the daemon died: no finished contour runs twice, nothing is skipped.
inline void expect_resumed_at_the_cut_short_contour(const std::vector<std::string>& lines, const std::vector<LogBlock>& ran_before,
                                             const std::vector<LogBlock>& log) {
  std::size_t done = 0;
  while (done < ran_before.size() && ran_before[done].line == lines[done]) ++done;
  ASSERT_EQ(done, ran_before.size()) << "the first run is the program in order";
  std::size_t finished = 0;  // lines that completed in the first run
  for (std::size_t i = 0; i < ran_before.size(); ++i)
    if (ran_before[i].completed) finished = i + 1;
  std::size_t contour_start = 0;
  for (std::size_t k = 0; k <= std::min(finished, lines.size() - 1); ++k)
    if (lines[k].rfind("(CONTOUR ", 0) == 0) contour_start = k;
  std::size_t resumed_at = log.size();
  for (std::size_t i = ran_before.size(); i < log.size(); ++i)
    if (log[i].line == lines[contour_start]) {
      resumed_at = i;
      break;
    }
  ASSERT_LT(resumed_at, log.size()) << "the resumed run starts at contour line " << contour_start + 1;
  ASSERT_EQ(log.size() - resumed_at, lines.size() - contour_start);
  for (std::size_t i = 0; i < lines.size() - contour_start; ++i)
    ASSERT_EQ(log[resumed_at + i].line, lines[contour_start + i]) << "resumed block " << i + 1;
}

// A small tmpfs over a folder: a disk that really fills up. Needs CAP_SYS_ADMIN (root on the CI
// machine); without it the test says so and skips.
class SmallDisk {
 public:
  SmallDisk(const std::string& folder, const std::string& size) : folder_(folder) {
    std::filesystem::create_directories(folder);
    const std::string options = "size=" + size + ",mode=0755";
    mounted_ = ::mount("tmpfs", folder.c_str(), "tmpfs", 0, options.c_str()) == 0;
    if (!mounted_) why_ = std::strerror(errno);
  }
  ~SmallDisk() {
    if (mounted_) ::umount2(folder_.c_str(), MNT_DETACH);
  }
  bool mounted() const { return mounted_; }
  const std::string& why() const { return why_; }
  // Writes a file until the disk is full; its size.
  std::size_t fill(const std::string& name) const {
    std::FILE* f = std::fopen((folder_ + "/" + name).c_str(), "wb");
    if (!f) return 0;
    const std::string block(64 * 1024, 'x');
    std::size_t written = 0;
    while (std::fwrite(block.data(), 1, block.size(), f) == block.size()) written += block.size();
    std::fclose(f);
    return written;
  }

 private:
  std::string folder_, why_;
  bool mounted_ = false;
};

// The example knob submitted on 5 mm stock, planned, its first sheet confirmed, and the CNC past
// `blocks_before` executed blocks; the job's id.
inline std::string start_cutting(RpcClient& c, Cell& cell, std::size_t blocks_before) {
  Json job = call_ok(c, "job.submit", {{"model", std::string(LAMINA_EXAMPLES_DIR) + "/knob.stl"}, {"settings", {{"stock", "5"}}}});
  const std::string id = job["id"];
  job = wait_state(c, id, "waiting_sheet", 120);
  if (job["state"] != "waiting_sheet") throw std::runtime_error("not planned: " + job.dump());
  call_ok(c, "job.confirm_sheet", {{"job", id}, {"sheet", 1}});
  if (!sim::testing::wait_status(cell.sim.control_port(),
                                 [&](const Json& s) { return s["executed_blocks"].get<std::size_t>() > blocks_before; }, 60))
    throw std::runtime_error("the cut did not start");
  return id;
}

}  // namespace lamina::daemon::testing
