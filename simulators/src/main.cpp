// lamina-sim: a software waterjet cell for tests and demos — a CNC on a PTY or TCP port
// (grbl or xonxoff personality), a PLC on Modbus TCP, a time model, faults on request and an
// execution log. See docs/simulator.md.
#include <atomic>
#include <csignal>
#include <cstdio>
#include <sstream>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "as_cut.hpp"
#include "coupon_reading.hpp"
#include "sim_options.hpp"
#include "sim_runtime.hpp"

#include <filesystem>
#include <fstream>

namespace {

std::atomic<bool> g_stop{false};
extern "C" void on_signal(int) { g_stop = true; }

lamina::sim::AxisValues parse_axes(const std::string& text, const char* flag) {
  lamina::sim::AxisValues out{};
  std::stringstream in(text);
  std::string item;
  int i = 0;
  while (std::getline(in, item, ',')) {
    if (i >= lamina::sim::kAxisCount) break;
    try {
      out[static_cast<std::size_t>(i)] = std::stod(item);
    } catch (const std::exception&) {
      throw std::runtime_error(fmt::format("{} '{}': '{}' is not a number", flag, text, item));
    }
    ++i;
  }
  if (i != lamina::sim::kAxisCount || in.rdbuf()->in_avail() > 0)
    throw std::runtime_error(fmt::format("{} '{}': expected 5 comma-separated numbers X,Y,Z,A,C", flag, text));
  return out;
}

// Options that are not fields of SimOptions as typed: applied after parsing (apply_options).
struct CliExtras {
  std::string machine_file, soft_min, soft_max;
  std::optional<std::uint64_t> drop_ok, alarm_at_line;
  std::optional<double> heartbeat_timeout_ms;
  std::size_t rx_buffer = 0, planner_blocks = 0;
  bool no_soft_limits = false;
  std::string on_open = "quiet";
};

void add_cell_options(CLI::App& app, lamina::sim::SimOptions& o, CliExtras& x) {
  app.add_option("--personality", o.personality, "grbl (character counting) or xonxoff (Fanuc drip feed)")
      ->check(CLI::IsMember({"grbl", "xonxoff"}));
  app.add_option("--link", o.link_path, "make a PTY and symlink its slave here");
  app.add_option("--tcp", o.tcp_address, "serve the CNC line on 127.0.0.1:PORT instead (0 = any port)");
  app.add_option("--modbus", o.modbus_address, "PLC Modbus TCP server on 127.0.0.1:PORT");
  app.add_option("--control", o.control_address, "fault/control socket on 127.0.0.1:PORT");
  app.add_option("--log", o.log_path, "execution log, JSON lines");
  app.add_option("--baud", o.baud, "emulated line speed, 8N1 (default 115200)");
  app.add_option("--time-scale", o.time_scale, "run the machine K times faster than real time");
  app.add_flag("--pace-to-host,!--no-pace-to-host", o.pace_to_host,
               "drop to real time while the controller holds under 1 s of motion and the host owes it more "
               "(a loaded test machine's pauses then cannot starve a host that keeps a real machine fed); "
               "--no-pace-to-host: the time scale throughout (the default)");
  app.add_option("--on-open", x.on_open,
                 "when a client opens the port: quiet (default: native-USB grblHAL says nothing), banner, or reset (a classic Grbl's DTR reset)")
      ->check(CLI::IsMember({"banner", "reset", "quiet"}));
  app.add_option("--rx-buffer", x.rx_buffer, "controller receive buffer in bytes (grbl 1024, classic Grbl 128)");
  app.add_option("--planner-blocks", x.planner_blocks, "planner queue length in blocks (default 100)");
  app.add_option("--machine", x.machine_file, "TOML file: soft limits, rapids, feeds, jet M-codes");
  app.add_option("--soft-min", x.soft_min, "soft limits, lower: X,Y,Z,A,C (mm, deg)");
  app.add_option("--soft-max", x.soft_max, "soft limits, upper: X,Y,Z,A,C (mm, deg)");
  app.add_flag("--no-soft-limits", x.no_soft_limits, "do not check soft limits");
  app.add_option("--heartbeat-timeout", x.heartbeat_timeout_ms, "PLC heartbeat watchdog in ms (0 = off)");
  app.add_option("--pressure-ramp", o.plc.pressure_ramp_s, "seconds for the pump to reach its set point");
}

void add_fault_options(CLI::App& app, lamina::sim::SimOptions& o, CliExtras& x) {
  app.add_option("--drop-ok", x.drop_ok, "never send the k-th ok (1-based)");
  app.add_option("--garble", o.faults.garble_probability, "flip a bit in each received byte with probability P");
  app.add_option("--seed", o.faults.garble_seed, "seed for --garble");
  app.add_option("--unplug-at-line", o.faults.unplug_at_line, "close the port once N lines were received");
  app.add_option("--unplug-at", o.faults.unplug_at_s, "close the port at simulated time T (s)");
  app.add_option("--replug-after", o.faults.replug_after_ms, "reopen the port this many ms after an unplug");
  app.add_option("--alarm-at-line", x.alarm_at_line, "ALARM:1 when block N starts executing");
  app.add_option("--estop-at", o.faults.estop_at_s, "press the e-stop at simulated time T (s)");
  app.add_option("--pressure-drop-at", o.faults.pressure_drop_at_s, "pump pressure drops at simulated time T (s)");
  app.add_option("--stall-at", o.faults.stall_at_s, "stop draining the receive buffer at simulated time T (s)");
  app.add_option("--stall-for", o.faults.stall_ms, "… for this many ms (wall clock)");
}

// The extras into the options; throws std::runtime_error naming the option that is wrong.
void apply_options(lamina::sim::SimOptions& o, const CliExtras& x) {
  using namespace lamina::sim;
  if (!x.machine_file.empty()) apply_machine_file(x.machine_file, o);
  o.on_open = x.on_open == "reset" ? OnOpen::reset : x.on_open == "banner" ? OnOpen::banner : OnOpen::quiet;
  if (x.rx_buffer) o.grbl.rx_buffer_bytes = o.xonxoff.buffer_bytes = x.rx_buffer;
  if (o.personality == "xonxoff") {  // water marks follow the buffer: DC3 at ¾, DC1 at ¼
    o.xonxoff.high_water_bytes = o.xonxoff.buffer_bytes * 3 / 4;
    o.xonxoff.low_water_bytes = o.xonxoff.buffer_bytes / 4;
    // A Fanuc reads G4 P in milliseconds and carries an O program number.
    o.machine.parse.dwell_p_unit_s = 0.001;
    o.machine.parse.accept_program_number = true;
  }
  if (x.planner_blocks) o.machine.planner_blocks = x.planner_blocks;
  if (!x.soft_min.empty()) o.machine.soft_min = parse_axes(x.soft_min, "--soft-min");
  if (!x.soft_max.empty()) o.machine.soft_max = parse_axes(x.soft_max, "--soft-max");
  if (x.no_soft_limits) o.machine.soft_limits = false;
  if (x.heartbeat_timeout_ms) o.plc.heartbeat_timeout_s = *x.heartbeat_timeout_ms / 1000.0;
  // The PLC runs on simulated time, but its watchdog supervises a host that runs on the wall
  // clock (like the baud): the timeout is wall milliseconds, so it stretches with the scale.
  o.plc.heartbeat_timeout_s *= o.time_scale;
  if (x.drop_ok) o.grbl.faults.drop_ok_index = o.xonxoff.faults.drop_ok_index = x.drop_ok;
  if (x.alarm_at_line) o.machine.alarm_at_seq = x.alarm_at_line;
  if (o.faults.garble_probability < 0 || o.faults.garble_probability > 1)
    throw std::runtime_error("--garble: a probability in [0, 1]");
}

// --measure-coupon: cut a calibration coupon's program on this machine (its head and jet from
// --machine) and write what a person would measure; no ports, no waiting. docs/jet.md.
struct MeasureOptions {
  std::string program, out;
  lamina::sim::ReadingParams reading;
  // --as-cut: cut a sheet's program and write what the jet cut out of it (as_cut.hpp)
  std::string as_cut_program, as_cut_out;
  int as_cut_sections = 8;
};

void add_measure_options(CLI::App& app, MeasureOptions& m) {
  app.add_option("--measure-coupon", m.program, "cut this coupon program (lamina calibrate coupon) and write its measurements, then exit");
  app.add_option("--sheet-thickness", m.reading.sheet_thickness_mm, "the coupon sheet's thickness, mm (default 10)")->check(CLI::PositiveNumber);
  app.add_option("--measure-out", m.out, "CSV of the measurements: label,top_width_mm,bottom_width_mm,trail_back_mm");
  app.add_option("--measure-noise", m.reading.width_noise_mm, "the caliper's spread, mm (default 0.01)")->check(CLI::NonNegativeNumber);
  app.add_option("--measure-seed", m.reading.seed, "seed of the measurement noise");
  app.add_option("--as-cut", m.as_cut_program, "cut this sheet program with this machine's jet and write the pieces it cut out, then exit");
  app.add_option("--as-cut-out", m.as_cut_out, "the as-cut sections (JSON; default: stdout)");
  app.add_option("--as-cut-sections", m.as_cut_sections, "depths the pieces are sectioned at (default 8)")->check(CLI::Range(1, 1000));
}

std::string read_program(const std::string& path, const char* option) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(fmt::format("{}: cannot read {}", option, path));
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

int write_as_cut(const lamina::sim::SimOptions& o, const MeasureOptions& m) {
  using namespace lamina::sim;
  const std::string text = read_program(m.as_cut_program, "--as-cut");
  AsCutParams params;
  params.sheet_thickness_mm = m.reading.sheet_thickness_mm;
  params.sections = m.as_cut_sections;
  auto cut = cut_program(text, o.machine, o.head.value_or(HeadGeometry{}), o.jet, params);
  if (!cut) throw std::runtime_error(m.as_cut_program + ": " + cut.error());
  const std::string name = std::filesystem::path(m.as_cut_program).filename().string();
  const std::string json = as_cut_json(*cut, name, text).dump();
  if (m.as_cut_out.empty()) {
    std::fwrite(json.data(), 1, json.size(), stdout);
    return 0;
  }
  // Written whole and renamed: a reader never sees half a file.
  const std::string partial = m.as_cut_out + ".partial";
  std::ofstream out(partial, std::ios::binary | std::ios::trunc);
  out << json;
  out.close();
  if (!out) throw std::runtime_error("--as-cut-out: cannot write " + partial);
  std::filesystem::rename(partial, m.as_cut_out);
  return 0;
}

int measure_coupon(const lamina::sim::SimOptions& o, const MeasureOptions& m) {
  using namespace lamina::sim;
  const std::string text = read_program(m.program, "--measure-coupon");
  auto readings = read_coupon(text, o.machine, o.head.value_or(HeadGeometry{}), o.jet, m.reading);
  if (!readings) throw std::runtime_error(m.program + ": " + readings.error());
  std::ofstream out(m.out.empty() ? "/dev/stdout" : m.out);
  out << "label,top_width_mm,bottom_width_mm,trail_back_mm\n";
  for (const CouponReading& r : *readings)
    out << fmt::format("{},{:.4f},{:.4f},{:.4f}\n", r.label, r.top_width_mm, r.bottom_width_mm, r.trail_back_mm);
  out.flush();
  if (!out) throw std::runtime_error("--measure-out: cannot write " + m.out);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace lamina::sim;
  SimOptions o;
  CliExtras x;
  CLI::App app{"lamina-sim: a simulated waterjet cell (CNC on a PTY/TCP, PLC on Modbus TCP)"};
  add_cell_options(app, o, x);
  add_fault_options(app, o, x);
  MeasureOptions measure;
  add_measure_options(app, measure);
  CLI11_PARSE(app, argc, argv);
  try {
    apply_options(o, x);
    if (!measure.program.empty()) return measure_coupon(o, measure);
    if (!measure.as_cut_program.empty()) return write_as_cut(o, measure);
    std::signal(SIGTERM, on_signal);
    std::signal(SIGINT, on_signal);
    std::signal(SIGPIPE, SIG_IGN);
    SimRuntime sim(std::move(o));
    // One JSON line on stdout tells a test (or the demo script) where everything is.
    std::puts(sim.ready_info().dump().c_str());
    std::fflush(stdout);
    sim.run(g_stop);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "lamina-sim: %s\n", e.what());
    return 1;
  }
  return 0;
}
