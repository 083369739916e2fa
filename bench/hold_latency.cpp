// Feed-hold latency measured at the controller. While a program streams by character counting
// over an emulated 115200-baud line to lamina-sim, holds are requested (each followed by a
// resume); every request's time on steady_clock is matched with the moment its '!' reached the
// simulated controller — the simulator's `realtime` log event, stamped on the same
// CLOCK_MONOTONIC. What it measures: the link's queues (ours, the kernel's PTY buffer) and the
// pacing of program bytes, i.e. what stands between the operator's hold and the wire.
//
// Two senders side by side in one run: program bytes paced to the line rate (what laminad and
// `lamina stream` do on a serial port) and unpaced (everything the controller has room for is
// written at once and waits in the kernel, ahead of any real-time byte).
//
// Usage: hold_latency [HOLDS] [TIME_SCALE]   (default 40 holds, machine 50× real time: the
// link, not the machine, is the bottleneck — the worst case for a real-time byte).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include <boost/asio/io_context.hpp>
#include <fmt/format.h>

#include "lamina/drivers/streamer.hpp"
#include "lamina/drivers/transport.hpp"
#include "sim_process.hpp"  // tests/simulators: lamina-sim as a process, its execution log

namespace {

using namespace std::chrono_literals;
namespace drivers = lamina::drivers;
namespace simt = lamina::sim::testing;

constexpr double kBaud = 115200;

double mono_s() { return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count(); }

// Short 2-axis cutting moves (0.5 mm at 3000 mm/min), the kind of program that fills a line.
std::vector<std::string> program(std::size_t moves) {
  std::vector<std::string> p{"G21G90G94", "G0X10Y10Z0", "M3", "G1F3000"};
  double x = 10, y = 10;
  for (std::size_t i = 0; i < moves; ++i) {
    x += 0.5 * std::cos(static_cast<double>(i) * 0.002);
    y += 0.5 * std::sin(static_cast<double>(i) * 0.002);
    if (x > 2900 || y > 1900) x = y = 10;
    p.push_back(fmt::format("X{:.3f}Y{:.3f}", x, y));
  }
  p.insert(p.end(), {"M5", "M30"});
  return p;
}

struct Percentiles {
  double p50_ms = 0, p95_ms = 0, max_ms = 0;
  std::size_t count = 0;
};

Percentiles percentiles(std::vector<double> ms) {
  Percentiles p;
  p.count = ms.size();
  if (ms.empty()) return p;
  std::sort(ms.begin(), ms.end());
  const auto at = [&](double q) { return ms[std::min(ms.size() - 1, static_cast<std::size_t>(q * (ms.size() - 1) + 0.5))]; };
  p.p50_ms = at(0.50);
  p.p95_ms = at(0.95);
  p.max_ms = ms.back();
  return p;
}

Percentiles measure(bool paced, int holds, double time_scale) {
  simt::TempDir dir;
  const std::string link_path = dir.file("cnc"), log_path = dir.file("exec.jsonl");
  simt::SimProcess sim({"--link", link_path, "--log", log_path, "--baud", fmt::format("{}", kBaud), "--time-scale",
                        fmt::format("{}", time_scale), "--no-soft-limits"});
  drivers::StreamerSettings settings;
  settings.pace_bytes_per_s = paced ? kBaud / 10 : 0;
  drivers::SerialSettings serial;
  serial.baud = static_cast<int>(kBaud);
  drivers::Streamer link([&](boost::asio::io_context& io) { return drivers::open_serial(io, link_path, serial); },
                         drivers::make_grbl_protocol(), settings);
  link.start(drivers::LineSpan{program(200000), 0}, {});
  std::this_thread::sleep_for(1500ms);  // handshake done, the controller's buffer full

  std::mt19937 rng(7);
  std::uniform_int_distribution<int> gap_ms(150, 350);
  std::vector<double> asked_s;
  for (int i = 0; i < holds; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(gap_ms(rng)));
    asked_s.push_back(mono_s());
    link.request(drivers::RealtimeCommand::feed_hold);
    std::this_thread::sleep_for(100ms);
    link.request(drivers::RealtimeCommand::resume);
  }
  std::this_thread::sleep_for(500ms);
  link.stop({drivers::LinkErrorCode::cancelled, "benchmark done"});
  link.wait(10);
  sim.stop();

  std::vector<double> arrived_s;
  for (const auto& r : simt::read_log(log_path))
    if (r.value("event", "") == "realtime" && r.value("command", "") == "feed_hold") arrived_s.push_back(r["mono_s"]);
  if (arrived_s.size() != asked_s.size())
    throw std::runtime_error(fmt::format("{} holds asked, {} reached the controller", asked_s.size(), arrived_s.size()));
  std::vector<double> ms;
  for (std::size_t i = 0; i < asked_s.size(); ++i) ms.push_back((arrived_s[i] - asked_s[i]) * 1000);
  return percentiles(ms);
}

}  // namespace

int main(int argc, char** argv) {
  const int holds = argc > 1 ? std::stoi(argv[1]) : 40;
  const double time_scale = argc > 2 ? std::stod(argv[2]) : 50;
  try {
    fmt::print("feed hold: request -> '!' at the controller, {} holds each, 115200 baud, machine {}x real time\n",
               holds, time_scale);
    for (const bool paced : {true, false}) {
      const Percentiles p = measure(paced, holds, time_scale);
      fmt::print("{:<9} p50 {:7.2f} ms   p95 {:7.2f} ms   max {:7.2f} ms   ({} holds)\n", paced ? "paced" : "unpaced",
                 p.p50_ms, p.p95_ms, p.max_ms, p.count);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "hold_latency: %s\n", e.what());
    return 1;
  }
  return 0;
}
