#pragma once
// One CutJob on lamina-sim with its PLC, cut on a thread of its own, for the tests of what the
// cell does while a program runs (holds, starvation): the simulator's log read back as events.
#include <algorithm>
#include <chrono>
#include <functional>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "lamina/drivers/cut_job.hpp"
#include "link_test_support.hpp"
#include "pty_link.hpp"

namespace lamina::drivers::testing {

struct SimCutOptions {
  bool with_plc = true;
  std::vector<std::string> program = contour_program(3, 150);
  double baud = 115200;  // the simulator's line and the host's pacing alike
  // The link to the simulator's PTY at `path` (default: grbl_pty_link at `baud`).
  std::function<std::unique_ptr<Streamer>(const std::string& path)> make_link = {};
};

struct SimCut {
  explicit SimCut(CutJobSettings settings, SimCutOptions options = {})
      : sim([&] {
          std::vector<std::string> args{"--link",    dir.file("cnc"), "--log", dir.file("exec.jsonl"), "--control",
                                        "127.0.0.1:0", "--time-scale", "1", "--baud", fmt::format("{}", options.baud)};
          if (options.with_plc) args.insert(args.end(), {"--modbus", "127.0.0.1:0", "--pressure-ramp", "0.2"});
          return args;
        }()),
        program(std::move(options.program)),
        link(options.make_link ? options.make_link(dir.file("cnc")) : grbl_pty_link(dir.file("cnc"), options.baud)) {
    if (options.with_plc) {
      CellIoSettings cs;
      cs.plc.port = sim.modbus_port();
      cell = std::make_unique<CellIo>(cs);
    }
    job = std::make_unique<CutJob>(*link, cell.get(), program, settings);
  }
  ~SimCut() {
    if (cutter.joinable()) cutter.join();
  }
  void start() {
    cutter = std::thread([this] { report = job->run(); });
  }
  CutReport finish() {
    cutter.join();
    return report;
  }
  bool cutting_with_the_jet_on() {
    return sim::testing::wait_status(sim.control_port(), [](const nlohmann::json& st) {
      return st["jet_commanded"] == true && st["executed_blocks"].get<int>() > 40 && st["state"] == "run";
    }, 30);
  }
  std::vector<nlohmann::json> events(const std::string& kind) const {
    std::vector<nlohmann::json> out;
    for (const auto& r : sim::testing::read_log(dir.file("exec.jsonl")))
      if (r.value("event", "") == kind) out.push_back(r);
    return out;
  }


  TempDir dir;
  SimProcess sim;
  std::vector<std::string> program;
  std::unique_ptr<Streamer> link;
  std::unique_ptr<CellIo> cell;
  std::unique_ptr<CutJob> job;
  std::thread cutter;
  CutReport report;
};

inline bool wait_for(const std::function<bool()>& ready, double wait_s) {
  const auto t0 = std::chrono::steady_clock::now();
  while (std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() < wait_s) {
    if (ready()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return false;
}

}  // namespace lamina::drivers::testing
