#include "sim_runtime.hpp"

#include <poll.h>
#include <sstream>
#include <stdexcept>
#include <thread>
#include <vector>

#include <fmt/format.h>

#include "grbl_protocol.hpp"
#include "net_util.hpp"
#include "xonxoff_protocol.hpp"

namespace lamina::sim {
namespace {

// A late wake-up of up to 20 ms is caught up at once; longer gaps are not (the wire idled).
constexpr double kBurstS = 0.020;

std::unique_ptr<CncProtocol> make_protocol(const SimOptions& o, Machine& machine) {
  if (o.personality == "grbl") return make_grbl_protocol(machine, o.grbl);
  if (o.personality == "xonxoff") return make_xonxoff_protocol(machine, o.xonxoff);
  throw std::runtime_error(fmt::format("--personality '{}': expected grbl or xonxoff", o.personality));
}

const char* state_name(MachineState s) {
  switch (s) {
    case MachineState::idle: return "idle";
    case MachineState::run: return "run";
    case MachineState::hold_pending: return "hold_pending";
    case MachineState::hold: return "hold";
    case MachineState::alarm: return "alarm";
  }
  return "?";
}

int state_code(MachineState s) {  // as the PLC's cnc_state register (docs/modbus-map.md)
  switch (s) {
    case MachineState::idle: return 0;
    case MachineState::run: return 1;
    case MachineState::hold_pending: return 2;
    case MachineState::hold: return 3;
    case MachineState::alarm: return 4;
  }
  return 0;
}

const char* on_open_name(OnOpen o) {
  switch (o) {
    case OnOpen::banner: return "banner";
    case OnOpen::reset: return "reset";
    case OnOpen::quiet: return "quiet";
  }
  return "?";
}

}  // namespace

SimRuntime::SimRuntime(SimOptions options)
    : options_(std::move(options)),
      clock_(options_.time_scale),
      machine_(options_.machine),
      rx_pacer_(options_.baud / 10.0, kBurstS),
      tx_pacer_(options_.baud / 10.0, kBurstS),
      log_(options_.log_path, options_.head),
      plc_(options_.plc),
      garble_rng_(options_.faults.garble_seed),
      scale_asked_(options_.time_scale) {
  if (!(options_.baud > 0)) throw std::runtime_error("--baud must be positive");
  if (!(options_.time_scale > 0)) throw std::runtime_error("--time-scale must be positive");
  protocol_ = make_protocol(options_, machine_);
  if (!options_.link_path.empty() && !options_.tcp_address.empty())
    throw std::runtime_error("give --link or --tcp, not both (one serial line per controller)");
  if (!options_.link_path.empty()) {
    port_ = open_pty_port(options_.link_path);
  } else if (!options_.tcp_address.empty()) {
    const auto [host, port] = parse_loopback_address(options_.tcp_address, "--tcp");
    port_ = open_tcp_port(host, port);
  } else {
    throw std::runtime_error("no CNC port: give --link PATH (a PTY) or --tcp 127.0.0.1:PORT");
  }
  if (!options_.modbus_address.empty()) {
    const auto [host, port] = parse_loopback_address(options_.modbus_address, "--modbus");
    modbus_ = std::make_unique<ModbusServer>(host, port, plc_, plc_mutex_, [this] { return sim_s(); });
  }
  if (!options_.control_address.empty()) {
    const auto [host, port] = parse_loopback_address(options_.control_address, "--control");
    control_ = std::make_unique<ControlSocket>(host, port);
  }
  // Power-up: the controller prints its banner even before anyone listens (grblHAL does).
  protocol_->on_connect(0.0);
  log_.write_event("start", 0.0, {{"personality", options_.personality}, {"port", port_->describe()},
                                  {"on_open", on_open_name(options_.on_open)},
                                  {"baud", options_.baud}, {"time_scale", options_.time_scale}});
}

SimRuntime::~SimRuntime() = default;

nlohmann::json SimRuntime::ready_info() const {
  nlohmann::json info{{"ready", true}, {"personality", options_.personality}};
  if (!options_.link_path.empty()) info["link"] = options_.link_path;
  if (!options_.tcp_address.empty()) info["tcp_port"] = tcp_port_number(*port_);
  if (modbus_) info["modbus_port"] = modbus_->port();
  if (control_) info["control_port"] = control_->port();
  if (!options_.log_path.empty()) info["log"] = options_.log_path;
  return info;
}

void SimRuntime::run(const std::atomic<bool>& stop) {
  while (!stop.load()) {
    step();
    std::vector<pollfd> fds;
    // Input the controller cannot take yet stays in the port: no wake-up for it (a busy loop).
    if (int fd = port_->poll_fd(); fd >= 0 && protocol_->input_room() > 0) fds.push_back({fd, POLLIN, 0});
    if (control_)
      for (int fd : control_->poll_fds()) fds.push_back({fd, POLLIN, 0});
    // 1 ms granularity: a byte at 115200 baud takes 87 µs, so bytes move in small bursts that
    // the pacer keeps at the right average rate.
    ::poll(fds.data(), fds.size(), 1);
  }
  log_.write_event("stop", sim_s());
}

void SimRuntime::step() {
  const double wall = wall_s();
  const double now = sim_at_with_knee(wall);

  switch (port_->update()) {
    case PortChange::client_connected:
      log_.write_event("connect", now, {{"on_open", on_open_name(options_.on_open)}});
      // What the controller said before the host opened the port (the power-up banner
      // included) went nowhere, as on native USB before the host enumerates it.
      discard_output();
      protocol_->on_output_sent(protocol_->take_output().size());
      switch (options_.on_open) {
        case OnOpen::banner: protocol_->on_connect(now); break;
        case OnOpen::reset:  // the reset prints the banner itself (after ALARM:3 if it was moving)
          reset_cnc(now, "open");
          break;
        case OnOpen::quiet: break;
      }
      break;
    case PortChange::client_gone:
      log_.write_event("disconnect", now);
      break;
    case PortChange::none: break;
  }
  apply_schedule(wall, now);
  move_bytes_in(wall, now);
  machine_.advance(now);
  const bool stalled_by_coil = [&] {
    std::lock_guard lock(plc_mutex_);
    return plc_.stall();
  }();
  protocol_->set_stalled(stalled_by_coil || (stall_until_wall_ && wall < *stall_until_wall_));
  if (stall_until_wall_ && wall >= *stall_until_wall_) {
    stall_until_wall_.reset();
    log_.write_event("stall_end", now);
  }
  protocol_->poll(now);
  pace_to_host(now);
  tick_plc(now);
  for (const auto& event : machine_.take_events()) log_.write(event);
  log_jet_and_state(now);
  protocol_->set_bytes_in_transit(std::min(port_->input_waiting(), rx_pacer_.bytes_behind_bound()));
  tx_pending_ += protocol_->take_output();
  move_bytes_out(wall);
  if (control_) control_->serve([this](const std::string& line) { return handle_command(line); });
}

void SimRuntime::move_bytes_in(double wall, double now) {
  std::size_t allowed = rx_pacer_.allowance(wall);
  if (!port_->client_present()) return;
  std::uint8_t buffer[4096];
  std::bernoulli_distribution garble(options_.faults.garble_probability);
  std::uniform_int_distribution<int> bit(0, 7);
  while (allowed > 0) {
    const std::size_t room = protocol_->input_room();
    if (room == 0) break;  // the controller is turning the line round (its DC3 goes out first)
    const long n = port_->read_some(buffer, std::min({allowed, room, sizeof buffer}));
    if (n <= 0) {
      rx_pacer_.idle();  // the client's queue is empty: the wire idles
      break;
    }
    rx_pacer_.consume(static_cast<std::size_t>(n));
    allowed -= static_cast<std::size_t>(n);
    if (lag_pending_s_) oversleep(now);
    for (long i = 0; i < n; ++i) {
      std::uint8_t byte = buffer[i];
      if (options_.faults.garble_probability > 0 && garble(garble_rng_)) {
        // Line noise flips a bit: the controller sees another byte, as on a real cable.
        const std::uint8_t was = byte;
        byte = static_cast<std::uint8_t>(byte ^ (1u << bit(garble_rng_)));
        ++bytes_garbled_;
        log_.write_event("garble", now, {{"from", was}, {"to", byte}});
      }
      if (options_.personality == "grbl") log_realtime_byte(byte, now);
      protocol_->on_byte(byte, now);
      if (byte == '\n') ++line_ends_in_;
      // Unplug right after the N-th line's end: the bytes after it never reach the controller.
      if (options_.faults.unplug_at_line && !schedule_unplug_done_ &&
          line_ends_in_ >= *options_.faults.unplug_at_line) {
        schedule_unplug_done_ = true;
        unplug(now, fmt::format("line {}", *options_.faults.unplug_at_line));
        return;
      }
    }
  }
}

// The emulation's own fault: the process sleeps as a loaded machine deschedules it, right
// after bytes arrived (mid-stream, when the sender is busy). The sender goes on writing on its
// own clock; what the wire would have carried meanwhile is waiting when the loop wakes.
void SimRuntime::oversleep(double now) {
  const double s = *std::exchange(lag_pending_s_, std::nullopt);
  log_.write_event("lag", now, {{"ms", s * 1000}});
  std::this_thread::sleep_for(std::chrono::duration<double>(s));
}

// The jet as the part feels it: water flows while the CNC's M-code asks for it and (with a
// PLC) the PLC's consent is on. Logged on change, and the machine's state on change, so a test
// or the fault campaign can measure how long a jet stood on a machine that did not move.
void SimRuntime::log_jet_and_state(double now) {
  bool flowing = machine_.jet_commanded();
  if (modbus_) {
    std::lock_guard lock(plc_mutex_);
    flowing = flowing && plc_.jet_is_on();
  }
  const char* state = state_name(machine_.state());
  if (flowing != jet_flowing_) {
    jet_flowing_ = flowing;
    log_.write_event("jet", now, {{"flowing", flowing}, {"state", state}});
  }
  if (state != logged_state_) {
    logged_state_ = state;
    log_.write_event("state", now, {{"state", state}, {"jet", flowing}});
  }
}

// Hold, resume and reset as they reach the controller, stamped on CLOCK_MONOTONIC (steady_clock),
// which every process on the machine shares: a host that notes when it asked can measure its
// real-time path to the controller, queues and pacing included (bench/hold_latency). Status
// polls (`?`) are not logged: they come five times a second.
void SimRuntime::log_realtime_byte(std::uint8_t byte, double now) {
  const char* name = nullptr;
  switch (byte) {
    case '!': case 0x82: name = "feed_hold"; break;
    case '~': case 0x81: name = "cycle_start"; break;
    case 0x18: name = "reset"; break;
    default: return;
  }
  const double mono_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
  log_.write_event("realtime", now, {{"command", name}, {"mono_s", mono_s}});
}

void SimRuntime::move_bytes_out(double wall) {
  std::size_t allowed = tx_pacer_.allowance(wall);
  if (!port_->client_present()) {
    discard_output();  // nobody on the line: what the controller says is lost
    return;
  }
  if (tx_pending_.empty()) tx_pacer_.idle();  // nothing to say: the wire idles
  while (allowed > 0 && !tx_pending_.empty()) {
    const std::size_t n = std::min(allowed, tx_pending_.size());
    const long written = port_->write_some(reinterpret_cast<const std::uint8_t*>(tx_pending_.data()), n);
    if (written <= 0) break;
    protocol_->on_output_sent(static_cast<std::size_t>(written));
    tx_pacer_.consume(static_cast<std::size_t>(written));
    allowed -= static_cast<std::size_t>(written);
    tx_pending_.erase(0, static_cast<std::size_t>(written));
  }
}

void SimRuntime::discard_output() {
  protocol_->on_output_sent(tx_pending_.size());
  tx_pending_.clear();
}

// The CNC's reset, whoever pressed it: the controller stops and flushes (protocol), and a
// block still waiting in the PLC's mailbox goes with the rest of the program.
void SimRuntime::reset_cnc(double now, const char* source) {
  std::lock_guard lock(plc_mutex_);
  reset_cnc_locked(now);
  log_.write_event("reset", now, {{"source", source}});
}

void SimRuntime::reset_cnc_locked(double now) {
  protocol_->external_reset(now);
  if (plc_.discard_pending_block()) log_.write_event("mailbox_discarded", now, {{"why", "reset"}});
}

void SimRuntime::tick_plc(double now) {
  std::lock_guard lock(plc_mutex_);
  // The CNC's panel buttons wired through the PLC (coils 4…6): the same actions as the serial
  // line's real-time bytes, so a Modbus-fed controller can be held, resumed and reset. Taken
  // before the snapshot, so the state the PLC publishes already shows what a press did.
  if (const CncButtons pressed = plc_.take_cnc_buttons(); pressed.any()) {
    if (pressed.reset) reset_cnc_locked(now);
    if (pressed.feed_hold) machine_.feed_hold(now);
    if (pressed.cycle_start) machine_.cycle_start(now);
    log_.write_event("plc_button", now, {{"feed_hold", pressed.feed_hold}, {"cycle_start", pressed.cycle_start},
                                         {"reset", pressed.reset}});
  }
  CncSnapshot snap;
  // The PLC reads the CNC's state lamps: a grblHAL dwelling is Idle (mc_dwell plans nothing),
  // as its `?` report says, so a mailbox host sees the same idle a line host does.
  const MachineState state = machine_.state();
  snap.state = state_code(state == MachineState::run && machine_.dwelling() ? MachineState::idle : state);
  snap.executed_blocks = machine_.executed_blocks();
  const AxisValues pos = machine_.position(now);
  for (int i = 0; i < kAxisCount; ++i) snap.position[i] = pos[static_cast<std::size_t>(i)];
  snap.jet_request = machine_.jet_commanded();
  snap.free_blocks = machine_.free_blocks();
  plc_.tick(now, snap);
  // The e-stop chain reaches the CNC too: pressed → ALARM:10 / NAK.
  if (plc_.estop_pressed() != estop_applied_) {
    estop_applied_ = plc_.estop_pressed();
    machine_.set_estop(estop_applied_, now);
    log_.write_event(estop_applied_ ? "estop" : "estop_released", now);
  }
  // A block waiting in the mailbox dies with the program an alarm stopped.
  if (machine_.alarm() && plc_.discard_pending_block()) log_.write_event("mailbox_discarded", now, {{"why", "alarm"}});
  // Blocks written into the Modbus mailbox go into the same queue as the serial line's (a
  // motion block waits for a free planner block, other blocks pass at once).
  if (const auto block = plc_.pending_block(); block && machine_.has_room_for(block->text)) {
    if (machine_.submit_line(block->text, now) == GrblStatus::ok)
      plc_.accept_block(block->seq);
    else
      plc_.refuse_block(block->seq);
  }
}

void SimRuntime::unplug(double now, const std::string& why) {
  if (!port_->plugged()) return;
  port_->unplug();
  discard_output();
  ++unplugs_;
  unplugged_by_fault_ = true;
  log_.write_event("unplug", now, {{"why", why}, {"line_ends_in", line_ends_in_}});
  if (options_.faults.replug_after_ms) replug_at_wall_ = wall_s() + *options_.faults.replug_after_ms / 1000.0;
}

void SimRuntime::apply_schedule(double wall, double now) {
  const auto& f = options_.faults;
  if (!schedule_unplug_done_ && f.unplug_at_s && now >= *f.unplug_at_s) {
    schedule_unplug_done_ = true;
    unplug(now, fmt::format("t {}", *f.unplug_at_s));
  }
  if (replug_at_wall_ && wall >= *replug_at_wall_) {
    replug_at_wall_.reset();
    port_->replug();
    log_.write_event("replug", now);
  }
  if (!schedule_estop_done_ && f.estop_at_s && now >= *f.estop_at_s) {
    schedule_estop_done_ = true;
    std::lock_guard lock(plc_mutex_);
    plc_.set_estop(true);
  }
  if (!schedule_pressure_done_ && f.pressure_drop_at_s && now >= *f.pressure_drop_at_s) {
    schedule_pressure_done_ = true;
    std::lock_guard lock(plc_mutex_);
    plc_.set_pressure_drop(true);
    log_.write_event("pressure_drop", now);
  }
  if (!schedule_stall_done_ && f.stall_at_s && now >= *f.stall_at_s) {
    schedule_stall_done_ = true;
    stall_until_wall_ = wall + f.stall_ms / 1000.0;
    log_.write_event("stall", now, {{"ms", f.stall_ms}});
  }
}

double SimRuntime::sim_at_with_knee(double wall) {
  if (pace_knee_ && clock_.sim_at(wall) > *pace_knee_->slow_from_s) {
    const PaceDecision knee = *pace_knee_;
    pace_knee_.reset();
    pacer_.slowed_at_knee();
    log_.write_event("time_scale", *knee.slow_from_s, {{"from", clock_.scale()}, {"to", knee.slow_scale}, {"paced", true}});
    std::lock_guard lock(plc_mutex_);
    plc_.rescale_watchdog(*knee.slow_from_s, knee.slow_scale / clock_.scale());
    clock_.set_scale_from(*knee.slow_from_s, knee.slow_scale);
  }
  return clock_.sim_at(wall);
}

void SimRuntime::pace_to_host(double now) {
  if (!options_.pace_to_host) return;
  const std::size_t capacity = machine_.planner_blocks();
  const ControllerLead lead{machine_.motion_ahead_s(now), machine_.time_until_blocks_left(now, capacity / 2),
                            machine_.queued_timed_blocks(), capacity};
  const PaceDecision d = pacer_.decide(now, lead, machine_.runs_on_host_lines(), scale_asked_);
  if (d.scale != clock_.scale()) change_scale(now, d.scale, "paced");
  pace_knee_.reset();
  if (d.slow_from_s && d.slow_scale != d.scale) pace_knee_ = d;
}

void SimRuntime::change_scale(double now, double to, const char* reason) {
  const double from = clock_.scale();
  nlohmann::json fields{{"from", from}, {"to", to}};
  if (std::string_view(reason) == "paced") fields["paced"] = true;
  log_.write_event("time_scale", now, fields);
  std::lock_guard lock(plc_mutex_);
  clock_.set_scale(to);
  plc_.rescale_watchdog(now, to / from);
}

nlohmann::json SimRuntime::status_json() const {
  const double now = sim_s();
  const auto& c = protocol_->counters();
  nlohmann::json pos = nlohmann::json::array();
  for (double v : machine_.position(now)) pos.push_back(v);
  return {{"t", now},
          {"time_scale", scale_asked_},
          {"time_scale_now", clock_.scale()},
          {"paced_slowdowns", pacer_.slowdowns()},
          {"state", state_name(machine_.state())},
          {"position", pos},
          {"accepted_blocks", machine_.accepted_blocks()},
          {"executed_blocks", machine_.executed_blocks()},
          {"queued_blocks", machine_.queued_blocks()},
          {"queued_timed_blocks", machine_.queued_timed_blocks()},
          {"starvation", machine_.starvation_count()},
          {"lines_received", c.lines_received},
          {"bytes_received", c.bytes_received},
          {"bytes_dropped", c.bytes_dropped},
          {"bytes_garbled", bytes_garbled_},
          {"oks_sent", c.oks_sent},
          {"oks_dropped", c.oks_dropped},
          {"errors_sent", c.errors_sent},
          {"rx_free", protocol_->rx_free()},
          {"client_present", port_->client_present()},
          {"plugged", port_->plugged()},
          {"unplugs", unplugs_},
          {"jet_commanded", machine_.jet_commanded()}};
}

// The campaign's controls (docs/reliability.md): the clock's rate and the PLC's network.
// Throws std::invalid_argument on a bad number, as handle_command's other commands do.
std::optional<std::string> SimRuntime::clock_or_network_command(const std::string& verb, const std::string& arg,
                                                                double now) {
  if (verb == "time-scale") {
    const double k = std::stod(arg);
    if (!(k > 0 && k <= 1000)) return "error: time-scale K needs a factor in (0, 1000]";
    scale_asked_ = k;
    pace_knee_.reset();
    change_scale(now, k, "control");
    return "ok";
  }
  if (verb == "plc" && (arg == "down" || arg == "up")) {
    if (!modbus_) return "error: plc down|up needs the PLC (--modbus)";
    modbus_->set_network_up(arg == "up");
    log_.write_event(arg == "up" ? "plc_up" : "plc_down", now, {{"source", "control"}});
    return "ok";
  }
  return std::nullopt;
}

std::string SimRuntime::handle_command(const std::string& line) {
  std::istringstream in(line);
  std::string verb, arg;
  in >> verb >> arg;
  const double now = sim_s();
  const auto plc_fault = [&](auto&& apply, const char* event) {
    {
      std::lock_guard lock(plc_mutex_);
      apply();
    }
    log_.write_event(event, now, {{"source", "control"}});
    return std::string("ok");
  };
  try {
    if (verb == "status") return status_json().dump();
    if (verb == "estop" && (arg == "on" || arg == "off"))
      return plc_fault([&] { plc_.set_estop(arg == "on"); }, arg == "on" ? "estop_request" : "estop_release_request");
    if (verb == "door" && (arg == "open" || arg == "closed"))
      return plc_fault([&] { plc_.set_door_open(arg == "open"); }, arg == "open" ? "door_open" : "door_closed");
    if (verb == "pressure" && (arg == "drop" || arg == "restore"))
      return plc_fault([&] { plc_.set_pressure_drop(arg == "drop"); },
                       arg == "drop" ? "pressure_drop" : "pressure_restore");
    if (auto reply = clock_or_network_command(verb, arg, now)) return *reply;
    if (verb == "stall") {
      const double ms = std::stod(arg);
      if (!(ms > 0)) return "error: stall MS needs a positive number of milliseconds";
      stall_until_wall_ = wall_s() + ms / 1000.0;
      log_.write_event("stall", now, {{"ms", ms}, {"source", "control"}});
      return "ok";
    }
    if (verb == "lag") {
      const double ms = std::stod(arg);
      if (!(ms > 0)) return "error: lag MS needs a positive number of milliseconds";
      lag_pending_s_ = ms / 1000.0;
      return "ok";
    }
    if (verb == "unplug") {
      unplug(now, "control");
      return "ok";
    }
    if (verb == "replug") {
      port_->replug();
      replug_at_wall_.reset();
      log_.write_event("replug", now, {{"source", "control"}});
      return "ok";
    }
    if (verb == "alarm") {
      const int code = arg.empty() ? static_cast<int>(GrblAlarm::hard_limit) : std::stoi(arg);
      machine_.raise_alarm(static_cast<GrblAlarm>(code), now);
      return "ok";
    }
    if (verb == "reset") {  // the operator's reset button on the controller's panel
      reset_cnc(now, "control");
      return "ok";
    }
    if (verb == "garble") {
      const double p = std::stod(arg);
      if (!(p >= 0 && p <= 1)) return "error: garble P needs a probability in [0, 1]";
      options_.faults.garble_probability = p;
      return "ok";
    }
  } catch (const std::exception&) {
    return fmt::format("error: '{}' needs a number, got '{}'", verb, arg);
  }
  return fmt::format("error: unknown command '{}' (status, estop on|off, door open|closed, pressure drop|restore, "
                     "plc down|up, time-scale K, stall MS, lag MS, unplug, replug, alarm N, reset, garble P)", line);
}

}  // namespace lamina::sim
