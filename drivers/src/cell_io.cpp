// CellIo: one thread owns the libmodbus context (libmodbus blocks). Callers hand it commands
// (prepare_cut, finish_cut) through a queue and wait on a future; jet_off() is an atomic flag the
// thread checks before anything else. Worst-case jet_off latency on a healthy link: the request
// in flight finishes first, so one response timeout (plus one write round trip). When the link is
// failing, the off write goes through the bounded reconnects; meanwhile the heartbeat has stopped,
// so the PLC's watchdog closes the jet after its own timeout anyway.
#include "lamina/drivers/cell_io.hpp"

#include <atomic>
#include <condition_variable>
#include <deque>
#include <future>
#include <mutex>
#include <thread>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "cell_interlocks.hpp"
#include "modbus_client.hpp"
#include "plc_map.hpp"

namespace lamina::drivers {
namespace pm = plc_map;
using Clock = std::chrono::steady_clock;
using Result = std::expected<void, LinkError>;

namespace {
Clock::duration seconds(double s) { return std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(s)); }
LinkError interlock(std::string message) { return {LinkErrorCode::interlock, std::move(message)}; }
}  // namespace

struct CellIo::Impl {
  enum class Kind { prepare, finish, reset_cnc, hold_cnc, refresh, restore_jet };
  struct Command {
    Kind kind;
    std::promise<Result> done;
  };

  Impl(CellIoSettings s, std::unique_ptr<RegisterBus> b)
      : settings(std::move(s)),
        log(driver_logger("cell")),
        bus(b ? std::move(b) : make_modbus_bus(settings.plc, "cell")),
        client(*bus) {
    client.set_abort([this] { return stopping.load(); });
    thread = std::thread([this] { run(); });
  }

  CellIoSettings settings;
  std::shared_ptr<spdlog::logger> log;
  std::unique_ptr<RegisterBus> bus;  // the PLC (Modbus TCP unless a test gives its own)
  RegisterBus& client;               // used on the thread only
  std::thread thread;

  mutable std::mutex mutex;  // guards the queue and everything shared below
  std::condition_variable wake;
  std::deque<Command> commands;
  std::atomic<bool> jet_off_requested{false};
  std::atomic<bool> jet_pause_requested{false};
  std::atomic<bool> feed_hold_requested{false};
  std::atomic<bool> cycle_start_requested{false};
  Clock::time_point feed_hold_requested_at{}, cycle_start_requested_at{};  // under mutex
  std::atomic<bool> stopping{false};
  std::optional<CellFaultReport> fault;
  std::function<void(const CellFaultReport&)> callback;
  CellStatus status;

  // Thread-only state.
  bool monitoring = false;  // between a successful prepare_cut and finish_cut: heartbeat + polling
  // The heartbeat runs from the first prepared cut until the PLC is lost or CellIo ends, between
  // cuts too (issue 18): the PLC's watchdog is there to catch a dead laminad, and stopping the
  // beat after each sheet latched its alarm in every gap between sheets (then reset silently).
  bool beating = false;
  std::optional<Clock::time_point> last_beat_at;
  std::uint16_t heartbeat_value = 0;
  Clock::time_point next_heartbeat, next_poll;
  Clock::time_point next_idle_poll = Clock::now();

  Result submit(Kind kind) {
    std::future<Result> done;
    {
      std::lock_guard lock(mutex);
      commands.push_back(Command{kind, {}});
      done = commands.back().done.get_future();
    }
    wake.notify_all();
    return done.get();
  }

  void run() {
    while (true) {
      if (jet_off_requested.exchange(false)) write_jet_off("jet_off() requested");
      if (jet_pause_requested.exchange(false)) pause_jet();
      if (feed_hold_requested.exchange(false)) press_if_fresh(pm::kCoilCncFeedHold, "feed hold", feed_hold_requested_at);
      if (cycle_start_requested.exchange(false))
        press_if_fresh(pm::kCoilCncCycleStart, "cycle start", cycle_start_requested_at);
      if (stopping) break;
      std::optional<Command> command;
      {
        std::lock_guard lock(mutex);
        if (!commands.empty()) {
          command.emplace(std::move(commands.front()));
          commands.pop_front();
        }
      }
      if (command) {
        command->done.set_value(execute(command->kind));
        continue;
      }
      if (monitoring && Clock::now() >= next_heartbeat) beat();
      if (!monitoring && beating && Clock::now() >= next_heartbeat) idle_beat();
      if (monitoring && Clock::now() >= next_poll) poll();
      if (!monitoring && settings.idle_poll_period_s > 0 && Clock::now() >= next_idle_poll) idle_poll();
      const auto deadline = monitoring ? std::min(next_heartbeat, next_poll) : idle_deadline();
      std::unique_lock lock(mutex);
      wake.wait_until(lock, deadline,
                      [this] {
                        return !commands.empty() || jet_off_requested || jet_pause_requested || feed_hold_requested ||
                               cycle_start_requested || stopping;
                    });
    }
    // Best effort on the way out: the jet must not stay consented with nobody watching.
    if (client.connected() || monitoring) {
      if (auto r = client.write_bit(pm::kCoilJetOn, false); !r) log->warn("jet off at shutdown: {}", r.error().message);
    }
    std::lock_guard lock(mutex);
    for (auto& c : commands) c.done.set_value(std::unexpected(LinkError{LinkErrorCode::cancelled, "CellIo destroyed"}));
    commands.clear();
  }

  // A button press is a real-time request: pressed late, it lands on a machine that has moved on.
  // The fault campaign caught one: a feed hold asked while the PLC was off the network reached
  // the CNC seconds later, after the resume had reset it, and held the new program. A cycle
  // start that late would start a machine nobody is watching. So a press older than this is
  // dropped (logged); jet off, in the safe direction, is never dropped.
  static constexpr double kPressMaxAgeS = 0.5;
  void press_if_fresh(int coil, const char* button, const Clock::time_point& requested_at) {
    Clock::time_point at;
    {
      std::lock_guard lock(mutex);
      at = requested_at;
    }
    const double age_s = std::chrono::duration<double>(Clock::now() - at).count();
    if (age_s > kPressMaxAgeS) {
      log->warn("{} through the PLC dropped: asked {:.1f} s ago, the PLC was busy or unreachable", button, age_s);
      return;
    }
    const auto give_up_at = at + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(kPressMaxAgeS));
    if (auto r = client.write_bit_before(coil, true, give_up_at); !r)
      log->warn("{} through the PLC: {}", button, r.error().message);
  }
  void signal_press(std::atomic<bool>& flag, Clock::time_point& requested_at) {
    {
      std::lock_guard lock(mutex);
      requested_at = Clock::now();
    }
    signal(flag);
  }

  // Sets a flag the thread acts on. The mutex is taken so the thread cannot miss the wake-up
  // between checking its flags and starting to wait (it would then sleep a whole period).
  void signal(std::atomic<bool>& flag) {
    {
      std::lock_guard lock(mutex);
      flag = true;
    }
    wake.notify_all();
  }

  Result execute(Kind kind) {
    switch (kind) {
      case Kind::prepare: return prepare();
      case Kind::finish: return finish();
      case Kind::reset_cnc: return reset_cnc();
      case Kind::hold_cnc: return hold_cnc();
      case Kind::refresh: return read_inputs();
      case Kind::restore_jet: return restore_jet();
    }
    return {};
  }

  void write_jet_off(const char* why) {
    if (auto r = client.write_bit(pm::kCoilJetOn, false); !r)
      log->error("jet off ({}) failed: {}", why, r.error().message);
    else
      log->info("jet off: {}", why);
  }

  // Jet first (the independent off path), then the abrasive: with no jet it would only fill
  // the cutting head's mixing chamber.
  void pause_jet() {
    write_jet_off("the machine stands in a feed hold");
    if (auto r = client.write_bit(pm::kCoilAbrasiveEnable, false); !r)
      log->error("abrasive off (feed hold) failed: {}", r.error().message);
  }

  // Abrasive before the jet, as in prepare(); then the interlocks read back, so a resume into a
  // cell that cannot cut (pressure gone while held) fails here instead of moving dry.
  Result restore_jet() {
    if (auto r = client.write_bit(pm::kCoilAbrasiveEnable, true); !r) return r;
    if (auto r = client.write_bit(pm::kCoilJetOn, true); !r) return r;
    if (auto r = read_inputs(); !r) return r;
    if (auto f = check_interlocks(snapshot(), settings)) {
      write_jet_off(f->message.c_str());
      return std::unexpected(interlock("cannot resume the jet: " + f->message));
    }
    log->info("jet and abrasive on again after the feed hold");
    return {};
  }

  // Discrete inputs and the first input registers, decoded into `status`.
  Result read_inputs() {
    auto bits = client.read_input_bits(0, pm::kInputCount);
    if (!bits) return read_failed(bits.error());
    auto regs = client.read_input_registers(0, pm::kInExecutedHigh + 2);
    if (!regs) return read_failed(regs.error());
    std::lock_guard lock(mutex);
    decode_cell_inputs(*bits, *regs, status);
    status.read_at = Clock::now();
    status.connected = client.connected();
    status.reconnects = client.reconnects();
    return {};
  }
  // A reading that failed leaves the last values, but says whether the PLC is still there:
  // status() readers show values of an unreachable PLC as unknown.
  Result read_failed(LinkError error) {
    {
      std::lock_guard lock(mutex);
      status.connected = client.connected();
      status.reconnects = client.reconnects();
    }
    return std::unexpected(std::move(error));
  }
  CellStatus snapshot() const {
    std::lock_guard lock(mutex);
    return status;
  }

  // Sleeps up to `s`, waking early for jet_off() or shutdown (prepare_cut aborts then).
  bool interrupted_sleep(double s) {
    std::unique_lock lock(mutex);
    return wake.wait_for(lock, seconds(s), [this] { return jet_off_requested.load() || stopping.load(); });
  }
  std::optional<LinkError> aborted() {
    if (stopping) return LinkError{LinkErrorCode::cancelled, "prepare_cut: CellIo shutting down"};
    if (jet_off_requested) return LinkError{LinkErrorCode::cancelled, "prepare_cut: jet_off() requested meanwhile"};
    return std::nullopt;
  }

  // A failed prepare leaves the cell off: jet, abrasive, pump (best effort; the link may be the fault).
  Result fail(LinkError error) {
    const std::uint8_t off[3] = {0, 0, 0};
    if (auto r = client.write_bits(pm::kCoilPumpEnable, off); !r) log->warn("cell off after failure: {}", r.error().message);
    log->error("prepare_cut failed: {}", error.message);
    return std::unexpected(std::move(error));
  }

  Clock::time_point idle_deadline() const {
    auto deadline = settings.idle_poll_period_s > 0 ? next_idle_poll : Clock::now() + std::chrono::seconds(1);
    return beating ? std::min(deadline, next_heartbeat) : deadline;
  }

  // Heartbeats from the PLC's current value, so the first write is a change it counts.
  Result start_beating() {
    auto hb = client.read_registers(pm::kHoldHeartbeat, 1);
    if (!hb) return std::unexpected(hb.error());
    heartbeat_value = (*hb)[0];
    if (auto r = beat_once(); !r) return r;
    beating = true;
    return {};
  }

  // A heartbeat alarm found at prepare says why it latched: how long laminad had been silent.
  void say_why_heartbeat_alarm() const {
    if (!snapshot().alarm_latched || snapshot().alarm_code != pm::kAlarmHeartbeat) return;
    if (last_beat_at)
      log->warn("PLC alarm {} ({}): laminad's heartbeat had been silent for {:.1f} s (the PLC was unreachable or "
                "laminad stalled); resetting it",
                pm::kAlarmHeartbeat, pm::alarm_name(pm::kAlarmHeartbeat),
                std::chrono::duration<double>(Clock::now() - *last_beat_at).count());
    else
      log->warn("PLC alarm {} ({}): latched before this laminad beat (an earlier session ended or stalled); "
                "resetting it",
                pm::kAlarmHeartbeat, pm::alarm_name(pm::kAlarmHeartbeat));
  }

  Result reset_alarm() {
    log->info("PLC alarm {} ({}) latched: pressing alarm_reset", snapshot().alarm_code, pm::alarm_name(snapshot().alarm_code));
    if (auto r = client.write_bit(pm::kCoilAlarmReset, true); !r) return r;
    return read_inputs();
  }

  Result prepare() {
    {
      std::lock_guard lock(mutex);
      fault.reset();
    }
    monitoring = false;
    if (auto r = read_inputs(); !r) return fail(r.error());
    auto s = snapshot();
    if (!s.estop_ok) return fail(interlock("cannot prepare the cut: e-stop pressed (estop_ok = 0)"));
    if (!s.door_closed) return fail(interlock("cannot prepare the cut: door open (door_closed = 0)"));
    say_why_heartbeat_alarm();
    // Beats first: the PLC clears a heartbeat alarm only once they come again.
    if (!beating)
      if (auto r = start_beating(); !r) return fail(r.error());
    // An alarm whose cause is gone (e.g. a released e-stop) would keep the pump off; clear it.
    if (s.alarm_latched)
      if (auto r = reset_alarm(); !r) return fail(r.error());
    if (auto r = client.write_register(pm::kHoldPressureSetpoint, settings.pressure_setpoint_01mpa); !r)
      return fail(r.error());
    if (auto r = client.write_bit(pm::kCoilPumpEnable, true); !r) return fail(r.error());

    const auto pump_deadline = Clock::now() + seconds(settings.pump_ready_timeout_s);
    while (true) {
      if (auto r = read_inputs(); !r) return fail(r.error());
      s = snapshot();
      if (!s.estop_ok) return fail(interlock("e-stop pressed while the pump started (estop_ok = 0)"));
      if (!s.door_closed) return fail(interlock("door opened while the pump started (door_closed = 0)"));
      if (s.pump_ready) break;
      if (Clock::now() >= next_heartbeat)
        if (auto r = beat_once(); !r) return fail(r.error());
      if (Clock::now() >= pump_deadline)
        return fail(interlock(fmt::format("pump not ready after {} s, pressure {:.1f} MPa of {:.1f} MPa",
                                          settings.pump_ready_timeout_s, s.pressure_mpa,
                                          mpa_from_01mpa(settings.pressure_setpoint_01mpa))));
      if (interrupted_sleep(std::max(0.01, settings.poll_period_s))) return fail(*aborted());
    }

    if (auto r = client.write_register(pm::kHoldAbrasiveSetpoint, settings.abrasive_g_per_min); !r)
      return fail(r.error());
    if (auto r = client.write_bit(pm::kCoilAbrasiveEnable, true); !r) return fail(r.error());
    if (auto r = beat_once(); !r) return fail(r.error());
    // A heartbeat alarm the first press could not clear clears now that heartbeats come again.
    if (auto r = read_inputs(); !r) return fail(r.error());
    if (snapshot().alarm_latched) {
      if (auto r = reset_alarm(); !r) return fail(r.error());
      s = snapshot();
      if (s.alarm_latched)
        return fail(interlock(fmt::format("PLC alarm {} ({}) still latched after alarm_reset", s.alarm_code,
                                          pm::alarm_name(s.alarm_code))));
    }
    if (auto e = aborted()) return fail(*e);
    if (auto r = client.write_bit(pm::kCoilJetOn, true); !r) return fail(r.error());
    // jet_is_on is not required: a real PLC may report the valve itself, closed until the CNC's M-code.
    if (auto r = read_inputs(); r && !snapshot().jet_is_on) log->info("jet consent given; the valve reads closed");
    monitoring = true;
    next_poll = Clock::now();
    log->info("cut prepared: pressure {:.1f} MPa, abrasive {} g/min", snapshot().pressure_mpa, settings.abrasive_g_per_min);
    return {};
  }

  // The reset button, then the CNC's state as the PLC reads it until it is idle: its buffer
  // and queue are gone and it takes a new program. An alarm that outlives the reset (its cause
  // is still there) is reported with the state read.
  Result reset_cnc() {
    return press_and_wait(pm::kCoilCncReset, "reset", [](ControllerState s) { return s == ControllerState::idle; },
                          "idle");
  }

  // The feed-hold button, then the CNC's state until it stands still (held, idle, alarm, door).
  // Returning only then matters to whoever resets the CNC next over its own line: a press the
  // PLC hands on after that reset would hold the fresh program.
  Result hold_cnc() {
    return press_and_wait(pm::kCoilCncFeedHold, "feed hold", [](ControllerState s) {
      return s == ControllerState::hold || s == ControllerState::idle || s == ControllerState::alarm ||
             s == ControllerState::door;
    }, "still");
  }

  template <class Accept>
  Result press_and_wait(int coil, const char* button, Accept accept, const char* wanted) {
    if (auto r = client.write_bit(coil, true); !r) return r;
    log->info("CNC {} through the PLC", button);
    const auto deadline = Clock::now() + seconds(settings.cnc_reset_timeout_s);
    const auto cancelled = [&] {
      return std::unexpected(LinkError{LinkErrorCode::cancelled, fmt::format("CNC {}: CellIo shutting down", button)});
    };
    // The PLC hands the press on in its next scan; a state read before that is the old one.
    if (interrupted_sleep(std::max(0.01, settings.poll_period_s)) && stopping) return cancelled();
    while (true) {
      if (auto r = read_inputs(); !r) return r;
      const ControllerState state = snapshot().cnc_state;
      if (accept(state)) return {};
      if (Clock::now() >= deadline)
        return std::unexpected(LinkError{LinkErrorCode::timeout,
                                         fmt::format("the CNC is not {} {} s after the PLC's {} (state {})", wanted,
                                                     settings.cnc_reset_timeout_s, button, to_string(state))});
      if (interrupted_sleep(std::max(0.01, settings.poll_period_s))) {
        if (stopping) return cancelled();
        if (jet_off_requested.exchange(false)) write_jet_off("jet_off() requested");
      }
    }
  }

  Result finish() {
    monitoring = false;  // polling and interlock faults stop with the cut; the heartbeat goes on
    Result first = {};
    for (int coil : {pm::kCoilJetOn, pm::kCoilAbrasiveEnable, pm::kCoilPumpEnable})
      if (auto r = client.write_bit(coil, false); !r && first) first = std::unexpected(r.error());
    if (first) log->info("cut finished: jet, abrasive and pump off");
    (void)read_inputs();  // status() shows the cell as left, not as it was while cutting
    return first;
  }

  Result beat_once() {
    heartbeat_value = static_cast<std::uint16_t>(heartbeat_value + 1);  // always a change
    next_heartbeat = Clock::now() + seconds(settings.heartbeat_period_s);
    auto r = client.write_register(pm::kHoldHeartbeat, heartbeat_value);
    if (r) last_beat_at = Clock::now();
    return r;
  }
  // Between cuts no fault is raised (no cut to stop): the beat stops, said once, and starts
  // again with the next cut; the PLC's watchdog latches meanwhile, and that cut says why.
  void idle_beat() {
    if (auto r = beat_once(); !r) {
      beating = false;
      log->warn("the heartbeat between cuts failed ({}); it starts again with the next cut", r.error().message);
    }
  }
  void beat() {
    if (auto r = beat_once(); !r) link_lost(r.error());
  }

  void poll() {
    next_poll = Clock::now() + seconds(settings.poll_period_s);
    if (auto r = read_inputs(); !r) return link_lost(r.error());
    if (has_fault()) return;
    if (auto f = check_interlocks(snapshot(), settings)) {
      write_jet_off(f->message.c_str());  // first: the independent off path
      report(std::move(*f));
    }
  }

  // Between cuts: the inputs for status() only. Nothing is switched and no fault is raised (no
  // cut to stop); an unreachable PLC is logged once, and read as unknown by status() readers.
  void idle_poll() {
    const bool ok = read_inputs().has_value();
    next_idle_poll = Clock::now() + seconds(settings.idle_poll_period_s * (ok ? 1 : 5));
    if (!ok && idle_reachable) log->warn("the PLC does not answer between cuts; retrying every {} s", settings.idle_poll_period_s * 5);
    if (ok && !idle_reachable) log->info("the PLC answers again");
    idle_reachable = ok;
  }
  bool idle_reachable = true;

  void link_lost(const LinkError& error) {
    monitoring = false;
    beating = false;
    {
      std::lock_guard lock(mutex);
      status.connected = false;
      status.reconnects = client.reconnects();
    }
    report(CellFaultReport{CellFault::link_lost, error.message});
  }

  bool has_fault() const {
    std::lock_guard lock(mutex);
    return fault.has_value();
  }
  void report(CellFaultReport f) {
    std::function<void(const CellFaultReport&)> cb;
    {
      std::lock_guard lock(mutex);
      if (fault) return;  // sticky: the first fault is the one that stopped the cut
      fault = f;
      cb = callback;
    }
    log->error("cell fault: {}", f.message);
    if (cb) cb(f);
  }
};

CellIo::CellIo(CellIoSettings settings, std::unique_ptr<RegisterBus> bus)
    : impl_(std::make_unique<Impl>(std::move(settings), std::move(bus))) {}

CellIo::~CellIo() {
  impl_->signal(impl_->stopping);
  impl_->thread.join();
}

std::expected<void, LinkError> CellIo::prepare_cut() { return impl_->submit(Impl::Kind::prepare); }
std::expected<void, LinkError> CellIo::finish_cut() { return impl_->submit(Impl::Kind::finish); }

void CellIo::jet_off() { impl_->signal(impl_->jet_off_requested); }
std::expected<void, LinkError> CellIo::reset_cnc() { return impl_->submit(Impl::Kind::reset_cnc); }
std::expected<void, LinkError> CellIo::hold_cnc() { return impl_->submit(Impl::Kind::hold_cnc); }
void CellIo::feed_hold() { impl_->signal_press(impl_->feed_hold_requested, impl_->feed_hold_requested_at); }
void CellIo::cycle_start() { impl_->signal_press(impl_->cycle_start_requested, impl_->cycle_start_requested_at); }
void CellIo::pause_jet() { impl_->signal(impl_->jet_pause_requested); }
std::expected<void, LinkError> CellIo::restore_jet() { return impl_->submit(Impl::Kind::restore_jet); }
std::expected<void, LinkError> CellIo::refresh() { return impl_->submit(Impl::Kind::refresh); }

void CellIo::on_fault(std::function<void(const CellFaultReport&)> callback) {
  std::lock_guard lock(impl_->mutex);
  impl_->callback = std::move(callback);
}

std::optional<CellFaultReport> CellIo::fault() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->fault;
}

CellStatus CellIo::status() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->status;
}

}  // namespace lamina::drivers
