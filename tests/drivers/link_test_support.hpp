#pragma once
// Shared by the machine-link tests: programs with contour markers (as our posts write them),
// the `lamina stream` CLI run as a user runs it, and the simulator's execution log read back
// as program line indexes.
#include <signal.h>
#include <sys/wait.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <thread>
#include <utility>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "sim_process.hpp"

namespace lamina::drivers::testing {

using sim::testing::SimProcess;
using sim::testing::TempDir;

// `contours` contours of `moves` 0.5 mm moves each, in the shape our posts give them: marker,
// rapid at safe height, plunge, jet on, pierce dwell, moves (some inverse time with A/C), jet
// off, retract.
inline std::vector<std::string> contour_program(int contours, int moves, double feed_mm_per_min = 1800) {
  std::vector<std::string> p{"(TEST PROGRAM)", "G21G90G94G17", "G0X0Y0Z10A0C0"};
  for (int k = 0; k < contours; ++k) {
    const double x0 = 20 + 40 * k, y0 = 20;
    p.push_back(fmt::format("(CONTOUR {} L{}-1 OUTLINE 0 PASS 0 FREES)", k, k + 1));
    p.push_back(fmt::format("G0X{:.3f}Y{:.3f}Z10A0C0", x0, y0));
    p.push_back("Z0");
    p.push_back("M3");
    p.push_back("G4P0.05");
    for (int i = 1; i <= moves; ++i) {
      const double x = x0 + 0.5 * i, y = y0 + 0.2 * (i % 7);
      if (i % 5 == 0)
        p.push_back(fmt::format("G93G1X{:.3f}Y{:.3f}A{:.2f}C{:.2f}F{:.0f}", x, y, 5.0 * (i % 3), 2.0 * i,
                                2 * feed_mm_per_min));
      else if (i % 5 == 1 && i > 1)
        p.push_back(fmt::format("G94G1X{:.3f}Y{:.3f}F{:.0f}", x, y, feed_mm_per_min));
      else
        p.push_back(fmt::format("G1X{:.3f}Y{:.3f}F{:.0f}", x, y, feed_mm_per_min));
    }
    p.push_back("M5");
    p.push_back("G94G0Z10");
  }
  p.push_back("M30");
  return p;
}

inline std::string write_program(const TempDir& dir, const std::vector<std::string>& lines,
                                 const std::string& name = "program.nc") {
  const std::string path = dir.file(name);
  std::ofstream out(path);
  for (const auto& l : lines) out << l << "\n";
  return path;
}

struct CliRun {
  int exit_code = -1;
  nlohmann::json summary;  // the --json line (empty when none)
  std::string output;
};

// The summary is the line of JSON among the log lines on the same pipe.
inline nlohmann::json summary_of(const std::string& output) {
  nlohmann::json summary;
  for (std::size_t start = 0; start < output.size();) {
    auto end = output.find('\n', start);
    if (end == std::string::npos) end = output.size();
    const std::string line = output.substr(start, end - start);
    if (!line.empty() && line.front() == '{') {
      try {
        summary = nlohmann::json::parse(line);
      } catch (const std::exception&) {
      }
    }
    start = end + 1;
  }
  return summary;
}

inline CliRun finish_cli(std::FILE* pipe) {
  CliRun r;
  char chunk[4096];
  while (pipe && std::fgets(chunk, sizeof chunk, pipe)) r.output += chunk;
  const int status = pipe ? ::pclose(pipe) : -1;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.summary = summary_of(r.output);
  return r;
}

inline CliRun run_lamina_stream(const std::string& args) {
  // Under `timeout`: a CLI that hangs fails its test in minutes, not at ctest's 25-minute limit.
  const std::string command = fmt::format("timeout -k 5 180 '{}' stream {} --json 2>&1 < /dev/null", LAMINA_CLI, args);
  return finish_cli(::popen(command.c_str(), "r"));
}

// `lamina stream … --json` in the background, for what a test does while it cuts (a fault
// through the control socket once the jet is on, the operator's Ctrl-C).
class BackgroundStream {
 public:
  BackgroundStream(const TempDir& dir, const std::string& args) : pid_file_(dir.file("lamina-stream.pid")) {
    const std::string command = fmt::format("sh -c 'echo $$ > \"{}\"; exec timeout -k 5 180 \"{}\" stream {} --json' "
                                            "2>&1 < /dev/null",
                                            pid_file_, LAMINA_CLI, args);
    pipe_ = ::popen(command.c_str(), "r");
  }
  ~BackgroundStream() {
    if (pipe_) finish();
  }
  // Signals reach the CLI through `timeout`, which passes them on.
  bool signal(int sig) const {
    int pid = 0;
    for (int i = 0; i < 500 && pid <= 0; ++i) {
      std::ifstream(pid_file_) >> pid;
      if (pid <= 0) std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return pid > 0 && ::kill(pid, sig) == 0;
  }
  CliRun finish() { return finish_cli(std::exchange(pipe_, nullptr)); }

 private:
  std::string pid_file_;
  std::FILE* pipe_ = nullptr;
};

// The completed blocks of the execution log, as texts in execution order.
inline std::vector<std::string> executed_lines(const std::string& log_path, bool completed_only = true) {
  std::vector<std::string> out;
  for (const auto& r : sim::testing::executed_blocks(sim::testing::read_log(log_path)))
    if (!completed_only || r.value("completed", true)) out.push_back(r["line"]);
  return out;
}

}  // namespace lamina::drivers::testing
