// lamina stream: send a program to the CNC through the machine link, with the cell's PLC
// minding the pump and interlocks when --modbus is given. Progress on stderr, the keyboard holds
// (h or space), resumes (r) and aborts (q); a stopped cut is resumed only when the operator says
// so, from the start of the contour it was cutting.
#include <termios.h>
#include <unistd.h>

#include <atomic>
#include <expected>
#include <chrono>
#include <csignal>
#include <fstream>
#include <thread>

#include <boost/asio/io_context.hpp>
#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include "commands.hpp"
#include "lamina/drivers/cell_io.hpp"
#include "lamina/drivers/cut_job.hpp"
#include "lamina/drivers/link_factory.hpp"
#include "lamina/drivers/streamer.hpp"
#include "stream_terminal.hpp"

namespace lamina::cli {
namespace {

struct StreamOptions {
  std::string program;
  std::string port, tcp, modbus;
  std::string protocol = "grbl";
  int baud = 115200;
  std::size_t rx_buffer = 0;
  double status_hz = 5;
  double stall_margin_s = 2;
  double hold_limit_s = 600;
  double jet_restart_s = 1.0;
  bool json = false;
  bool resume = false;  // resume automatically after a stop? never: only the keyboard's R
};

std::pair<std::string, int> split_host_port(const std::string& text, const char* flag) {
  auto hp = drivers::parse_host_port(text);
  if (!hp) throw CLI::ValidationError(flag, fmt::format("'{}': expected HOST:PORT (\"[::1]:PORT\" for IPv6)", text));
  return *hp;
}

std::expected<std::vector<std::string>, std::string> read_program(const std::string& path) {
  std::ifstream in(path);
  if (!in) return std::unexpected(fmt::format("cannot read {}", path));
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (!line.empty()) lines.push_back(line);  // a blank line means nothing to a controller
  }
  if (lines.empty()) return std::unexpected(fmt::format("{}: no program lines", path));
  return lines;
}

std::atomic<bool> g_interrupted{false};
extern "C" void on_sigint(int) { g_interrupted = true; }

// The end of a stream: one JSON line for a script (--json), or two lines for a person.
void print_summary(const drivers::CutReport& report, drivers::MachineLink* link, double line_bytes_per_s, bool json) {
  const double utilisation = line_bytes_per_s > 0 && report.seconds > 0
                                 ? static_cast<double>(report.bytes_sent) / (report.seconds * line_bytes_per_s)
                                 : 0;
  if (json) {
    nlohmann::json j{{"state", drivers::to_string(report.state)},
                     {"lines", report.lines_total},
                     {"lines_accepted", report.lines_accepted},
                     {"bytes", report.bytes_sent},
                     {"seconds", report.seconds},
                     {"link_utilisation", utilisation},
                     {"first_unfinished_line", report.first_unfinished_line + 1}};
    if (report.reason) j["reason"] = {{"code", drivers::to_string(report.reason->code)}, {"message", report.reason->message}};
    if (report.resume) j["resume"] = {{"line", report.resume->restart_index + 1}, {"contour", report.resume->contour}};
    if (auto* s = dynamic_cast<drivers::Streamer*>(link)) {
      const auto l = s->realtime_latency();
      j["realtime_latency_ms"] = {{"max", l.max_s * 1e3}, {"mean", l.mean_s * 1e3}, {"count", l.count}};
    }
    fmt::print("{}\n", j.dump());
  } else {
    fmt::print("{}: {} of {} lines, {} bytes in {:.1f} s", drivers::to_string(report.state), report.lines_accepted,
               report.lines_total, report.bytes_sent, report.seconds);
    if (utilisation > 0) fmt::print(", link {:.0f} % busy", 100 * utilisation);
    fmt::print("\n");
    if (report.reason) fmt::print("reason: {}\n", report.reason->message);
  }
}

// The link (built where laminad builds its own: drivers::make_link) and the cell the options name.
struct StreamRig {
  std::unique_ptr<drivers::MachineLink> link;
  const drivers::LinkProtocol* protocol = nullptr;
  std::unique_ptr<drivers::CellIo> cell;
  double line_bytes_per_s = 0;  // 0: not a serial line
};

// The rig, or the exit code after a usage error was printed.
std::expected<StreamRig, int> build_rig(const StreamOptions& o) {
  const drivers::LinkProtocol* protocol = drivers::find_link_protocol(o.protocol);  // --protocol was checked
  drivers::LinkSettings settings{o.protocol, o.port, o.tcp, o.baud, o.rx_buffer, o.status_hz, o.stall_margin_s, {}};
  if (protocol->traits.mailbox) {
    if (o.modbus.empty()) {
      fmt::print(stderr, "lamina stream: --protocol {} needs --modbus HOST:PORT\n", protocol->name);
      return std::unexpected(2);
    }
    std::tie(settings.plc.host, settings.plc.port) = split_host_port(o.modbus, "--modbus");
    settings.port.clear(), settings.tcp.clear();
  } else if (o.port.empty() == o.tcp.empty()) {
    fmt::print(stderr, "lamina stream: give --port DEVICE or --tcp HOST:PORT\n");
    return std::unexpected(2);
  } else if (!o.tcp.empty()) {
    (void)split_host_port(o.tcp, "--tcp");  // a usage error in the flag's own words
  }
  auto built = drivers::make_link(settings);
  if (!built) {
    fmt::print(stderr, "lamina stream: {}\n", built.error());
    return std::unexpected(2);
  }
  StreamRig rig{std::move(built->link), built->protocol, nullptr, built->line_bytes_per_s};
  if (!o.modbus.empty()) {  // the same PLC minds the pump and interlocks
    drivers::CellIoSettings cs;
    std::tie(cs.plc.host, cs.plc.port) = split_host_port(o.modbus, "--modbus");
    rig.cell = std::make_unique<drivers::CellIo>(cs);
  } else if (!protocol->traits.reports_status) {
    // Without the PLC's jet output, a stop can only hold the feed; a drip feed has no reset
    // on its line that would turn the controller's jet M-code off.
    spdlog::warn("no --modbus: on a stop nothing turns the jet off (a drip feed has no reset on its line); "
                 "use the cell's PLC");
  } else {
    spdlog::info("no --modbus: on a stop the controller is soft-reset once it stands still, to turn the jet off");
  }
  return rig;
}

int run_stream(const StreamOptions& o) {
  // Logs go to stderr: stdout carries the summary (--json) a script reads.
  spdlog::set_default_logger(spdlog::stderr_color_mt("link"));
  auto program = read_program(o.program);
  if (!program) {
    fmt::print(stderr, "lamina stream: {}\n", program.error());
    return 1;
  }
  auto rig = build_rig(o);
  if (!rig) return rig.error();
  auto& link = rig->link;
  auto& cell = rig->cell;

  drivers::CutJobSettings job_settings = drivers::cut_settings_for(*rig->protocol);
  job_settings.hold_limit_s = o.hold_limit_s;
  job_settings.jet_restart_s = o.jet_restart_s;
  drivers::CutJob job(*link, cell.get(), *program, job_settings);
  KeyboardControl keys;  // raw stdin while streaming when it is a terminal
  ProgressLine progress(program->size(), !o.json);
  std::signal(SIGINT, on_sigint);
  std::atomic<bool> finished{false};
  std::thread watcher([&] {
    while (!finished) {
      if (g_interrupted.exchange(false)) job.abort("interrupted (Ctrl-C)");
      switch (keys.poll()) {
        case Key::hold: job.hold(); break;
        case Key::resume: job.continue_motion(); break;
        case Key::quit: job.abort("aborted from the keyboard"); break;
        case Key::none: break;
      }
      progress.update(job.report());
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
  });
  drivers::CutReport report = job.run();
  while (report.state == drivers::CutState::stopped && keys.interactive()) {
    progress.clear();
    fmt::print(stderr, "\nstopped: {}\n", report.reason ? report.reason->message : "?");
    if (report.resume)
      fmt::print(stderr, "press R to resume at line {} (contour {}), Q to quit\n", report.resume->restart_index + 1,
                 report.resume->contour);
    if (!report.resume || keys.wait_resume_or_quit() != Key::resume) break;
    report = job.resume();
  }
  finished = true;
  watcher.join();
  progress.clear();
  // The stop kept the pump pressurised for a resume; this program is leaving, so nobody will
  // resume: jet, abrasive and pump off (a completed cut did that already).
  if (cell && report.state != drivers::CutState::completed)
    if (auto off = cell->finish_cut(); !off) spdlog::error("cell: could not turn the pump off: {}", off.error().message);

  print_summary(report, link.get(), rig->line_bytes_per_s, o.json);
  return report.state == drivers::CutState::completed ? 0 : 1;
}

}  // namespace

void add_stream_command(CLI::App& app, int& exit_code) {
  auto o = std::make_shared<StreamOptions>();
  auto* cmd = app.add_subcommand("stream", "send a program to the CNC (character counting, send-response, XON/XOFF "
                                           "or the PLC's Modbus mailbox) with the cell's interlocks watched");
  cmd->add_option("program", o->program, "G-code file")->required();
  cmd->add_option("--port", o->port, "serial device or USB serial number (see lamina ports)");
  cmd->add_option("--tcp", o->tcp, "the controller's TCP stream, HOST:PORT");
  cmd->add_option("--protocol", o->protocol, drivers::link_protocol_names_text())
      ->check(CLI::IsMember(drivers::link_protocol_names()));
  cmd->add_option("--baud", o->baud, "serial speed (8N1)")->check(CLI::Range(300, 4000000));
  cmd->add_option("--rx-buffer", o->rx_buffer, "the controller's receive buffer (default: as it reports)");
  cmd->add_option("--modbus", o->modbus, "the cell PLC, HOST:PORT (and the mailbox for --protocol modbus)");
  cmd->add_option("--status-hz", o->status_hz, "status polls per second")->check(CLI::Range(0.5, 50.0));
  cmd->add_option("--stall-margin", o->stall_margin_s,
                  "seconds Idle with lines unanswered (plus a dwell's P) before the link calls it a stall")
      ->check(CLI::Range(0.5, 600.0));
  cmd->add_option("--hold-limit", o->hold_limit_s,
                  "seconds a feed hold may stand (jet off through the PLC) before it becomes a stop")
      ->check(CLI::Range(1.0, 86400.0));
  cmd->add_option("--jet-restart", o->jet_restart_s, "seconds from the jet on to the motion when a hold resumes")
      ->check(CLI::Range(0.0, 60.0));
  cmd->add_flag("--json", o->json, "print the summary as JSON (no progress bar)");
  cmd->callback([o, &exit_code] { exit_code = run_stream(*o); });
}

}  // namespace lamina::cli
