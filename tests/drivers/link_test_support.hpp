#pragma once
// Shared by the machine-link tests: programs with contour markers (as our posts write them),
// the `lamina stream` CLI run as a user runs it, and the simulator's execution log read back
// as program line indexes.
#include <cstdio>
#include <fstream>
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

inline CliRun run_lamina_stream(const std::string& args) {
  CliRun r;
  // Under `timeout`: a CLI that hangs fails its test in minutes, not at ctest's 25-minute limit.
  const std::string command = fmt::format("timeout -k 5 180 '{}' stream {} --json 2>&1 < /dev/null", LAMINA_CLI, args);
  FILE* pipe = ::popen(command.c_str(), "r");
  char chunk[4096];
  while (pipe && std::fgets(chunk, sizeof chunk, pipe)) r.output += chunk;
  const int status = pipe ? ::pclose(pipe) : -1;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  for (std::size_t start = 0; start < r.output.size();) {
    auto end = r.output.find('\n', start);
    if (end == std::string::npos) end = r.output.size();
    const std::string line = r.output.substr(start, end - start);
    if (!line.empty() && line.front() == '{') {
      try {
        r.summary = nlohmann::json::parse(line);
      } catch (const std::exception&) {
      }
    }
    start = end + 1;
  }
  return r;
}

// The completed blocks of the execution log, as texts in execution order.
inline std::vector<std::string> executed_lines(const std::string& log_path, bool completed_only = true) {
  std::vector<std::string> out;
  for (const auto& r : sim::testing::executed_blocks(sim::testing::read_log(log_path)))
    if (!completed_only || r.value("completed", true)) out.push_back(r["line"]);
  return out;
}

}  // namespace lamina::drivers::testing
