#pragma once
// The cell's PLC over Modbus TCP (libmodbus, on its own thread: libmodbus blocks). Register
// map: docs/modbus-map.md. Before a cut it brings the cell up (e-stop released, door closed,
// pump on and at pressure within a timeout, abrasive on, jet consent); during the cut it keeps
// the heartbeat going and watches pressure and interlocks; it owns the jet's independent off
// path (the jet_on coil). Transport errors (ETIMEDOUT, EIO…) lead to bounded, logged reconnects.
#include <chrono>
#include <cstdint>
#include <expected>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "lamina/drivers/controller_status.hpp"
#include "lamina/drivers/link_error.hpp"
#include "lamina/drivers/modbus_endpoint.hpp"
#include "lamina/drivers/register_bus.hpp"

namespace lamina::drivers {

struct CellIoSettings {
  ModbusEndpoint plc;
  double heartbeat_period_s = 0.2;       // the PLC's watchdog must be longer
  double poll_period_s = 0.025;          // interlocks, pressure and the CNC read this often while cutting
  // Between cuts the inputs are read this often (0: never), so e-stop, door and pressure show
  // as they are, not as the last cut left them; after a failed read, five times as far apart.
  double idle_poll_period_s = 1.0;
  std::uint16_t pressure_setpoint_01mpa = 3800;
  std::uint16_t abrasive_g_per_min = 350;
  double pump_ready_timeout_s = 10;      // pump on → pump_ready
  double min_pressure_fraction = 0.9;    // below this × set point while cutting: pressure fault
  double cnc_reset_timeout_s = 5;        // the PLC's reset (hold) button → the CNC reads idle (still)
};

enum class CellFault {
  estop,          // estop_ok fell
  door_open,      // door_closed fell
  pressure_low,   // pump_ready fell or pressure below min_pressure_fraction × set point
  plc_alarm,      // the PLC latched an alarm (heartbeat watchdog, mailbox…)
  link_lost,      // Modbus unreachable after max_reconnects
};

struct CellFaultReport {
  CellFault fault{};
  std::string message;  // what was read, e.g. "pressure 112.0 MPa < 342.0 MPa (0.9 × 380)"
};

struct CellStatus {
  bool connected = false;
  bool estop_ok = false, door_closed = false, pump_ready = false, jet_is_on = false, alarm_latched = false;
  // The CNC's own jet output (its jet-on M-code) as wired into the PLC. The water flows when
  // both this and jet_is_on (the valve's consent) are set.
  bool cnc_jet_request = false;
  double pressure_mpa = 0;
  double abrasive_g_per_min = 0;
  int alarm_code = 0;
  int reconnects = 0;
  // The CNC as the PLC sees it: blocks finished since power-on (comments included, one per
  // program line) — how far a controller without a status report of its own has got.
  std::optional<std::uint64_t> cnc_executed_blocks;
  ControllerState cnc_state = ControllerState::unknown;  // the CNC's state lamps as the PLC wires them
  // When the values above were last read from the PLC (nullopt: never). They are refreshed
  // while a cut is monitored, by refresh() and the commands, and between cuts every
  // idle_poll_period_s.
  std::optional<std::chrono::steady_clock::time_point> read_at;
};

class CellIo {
 public:
  // Starts the Modbus thread. Does not connect yet.
  // `bus`: the PLC's registers; none: Modbus TCP to settings.plc (tests give an in-memory PLC).
  explicit CellIo(CellIoSettings settings, std::unique_ptr<RegisterBus> bus = nullptr);
  ~CellIo();  // jet off (best effort), stops the thread
  CellIo(const CellIo&) = delete;
  CellIo& operator=(const CellIo&) = delete;

  // Blocking: connect, check e-stop and door, pump on with its set point, wait for pump_ready,
  // abrasive on, heartbeat running, jet consent (jet_on = 1). The error names the failed
  // condition and the value read.
  std::expected<void, LinkError> prepare_cut();
  // The independent off path: jet_on = 0 now, from any thread, ahead of anything queued.
  // Worst case on a healthy link: one response timeout (the request in flight finishes first).
  // During prepare_cut it also aborts the preparation (cancelled; the cell is switched off).
  void jet_off();
  // The PLC's feed-hold button (coil cnc_feed_hold): the motion's independent stop for
  // controllers whose line has no real-time hold (a drip-fed Fanuc). Right after jet_off().
  void feed_hold();
  // The PLC's cycle-start button (coil cnc_cycle_start): continues a held drip feed.
  // Both presses are dropped (logged) if the Modbus thread cannot make them within 0.5 s (the
  // PLC busy reconnecting): a late press lands on a machine that has moved on.
  void cycle_start();
  // A feed hold that stands still: jet and abrasive feed off now, from any thread (as
  // jet_off(), the abrasive after it); the pump stays pressurised for the resume.
  void pause_jet();
  // The resume of such a hold, blocking: abrasive feed on, jet consent on, and the PLC read
  // back — an error when the cell cannot cut any more (e-stop, door, pressure).
  std::expected<void, LinkError> restore_jet();
  // Blocking: read the PLC's inputs now (status() is otherwise refreshed every poll_period_s
  // while a cut is monitored, every idle_poll_period_s between cuts) — e.g. the CNC's
  // executed-block count after a restart.
  std::expected<void, LinkError> refresh();
  // The PLC's reset button (coil cnc_reset): flushes a controller that has no reset on its line.
  // Blocking: returns once the PLC reads the CNC idle again, or an error naming the state it
  // stayed in (an alarm whose cause is still there) after cnc_reset_timeout_s.
  std::expected<void, LinkError> reset_cnc();
  // The feed-hold button, blocking: returns once the PLC reads the CNC still (held, idle, alarm,
  // door), so the press cannot land after whatever the caller does next (a reset over the line
  // followed by a new program would otherwise start held). Timeout: cnc_reset_timeout_s.
  std::expected<void, LinkError> hold_cnc();
  // After the cut (or a stop): jet off, abrasive off, pump to idle (pump_enable = 0). Blocking.
  std::expected<void, LinkError> finish_cut();
  // While a cut is prepared, the first fault seen (sticky until the next prepare_cut); the
  // callback (set before prepare_cut) runs once on the Modbus thread when it happens; it must not
  // call prepare_cut/finish_cut (they wait for that thread). jet_off() from it is fine.
  void on_fault(std::function<void(const CellFaultReport&)> callback);
  std::optional<CellFaultReport> fault() const;
  CellStatus status() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace lamina::drivers
