#pragma once
// The cell PLC: pump, abrasive feeder, interlocks, jet valve, heartbeat watchdog and the
// G-code block mailbox, as a register image (docs/modbus-map.md) plus a time model.
// Pure and single-threaded; the Modbus server (modbus_server.hpp) serialises access to it.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "modbus_map.hpp"

namespace lamina::sim {

struct PlcConfig {
  double pressure_ramp_s = 2.0;             // 0 → set point
  double pressure_ready_fraction = 0.95;    // pump_ready when pressure ≥ this × set point
  std::uint16_t default_setpoint_01mpa = 3800;   // 380 MPa
  std::uint16_t default_abrasive_g_per_min = 350;
  double hopper_kg = 50.0;
  double heartbeat_timeout_s = 1.0;         // 0 disables the watchdog
  double pressure_drop_fraction = 0.3;      // pressure falls to this × set point on the fault
};

// A G-code block a client wrote into the mailbox, waiting for the CNC to take it.
struct MailboxBlock {
  std::uint16_t seq = 0;
  std::string text;
};

// Plain register image, the shape libmodbus's modbus_mapping_t has.
struct PlcRegisters {
  std::vector<std::uint8_t> coils = std::vector<std::uint8_t>(modbus_map::kCoilSimEnd, 0);
  std::vector<std::uint8_t> inputs = std::vector<std::uint8_t>(modbus_map::kInputCount, 0);
  std::vector<std::uint16_t> input_registers = std::vector<std::uint16_t>(modbus_map::kInCount, 0);
  std::vector<std::uint16_t> holding = std::vector<std::uint16_t>(modbus_map::kHoldCount, 0);
};

// What the CNC side tells the PLC each tick (the CNC owns its queue and position).
struct CncSnapshot {
  int state = 0;                 // as kInCncState
  std::uint64_t executed_blocks = 0;
  double position[5] = {0, 0, 0, 0, 0};  // mm / deg
  bool jet_request = false;
  std::size_t free_blocks = 0;
};

// CNC buttons pressed through coils 4…6 since the last take_cnc_buttons().
struct CncButtons {
  bool feed_hold = false;
  bool cycle_start = false;
  bool reset = false;
  bool any() const { return feed_hold || cycle_start || reset; }
};

class Plc {
 public:
  explicit Plc(PlcConfig config);
  // The simulated clock now runs `factor` times as fast against the wall (control `time-scale`):
  // the watchdog, which supervises a wall-clock host, keeps its wall timeout and the heartbeat's
  // wall age. Without the age, a slowdown would make a fresh heartbeat look stale.
  void rescale_watchdog(double now_s, double factor) {
    config_.heartbeat_timeout_s *= factor;
    last_heartbeat_s_ = now_s - (now_s - last_heartbeat_s_) * factor;
  }

  // Called after every Modbus write (the server passes the image it wrote into): latches
  // alarm_reset, counts heartbeat changes, takes a new mailbox sequence number.
  void after_client_write(double now_s);
  // Advance the pump/abrasive/heartbeat model and refresh the read-only registers.
  void tick(double now_s, const CncSnapshot& cnc);

  // Mailbox hand-over to the CNC: the block waiting, if any; accept() publishes the ack.
  std::optional<MailboxBlock> pending_block() const;
  void accept_block(std::uint16_t seq);
  void refuse_block(std::uint16_t seq);  // the CNC refused the text: latch kAlarmMailboxBadBlock
  // The CNC was reset or went into alarm: a block not yet taken is dropped, never acknowledged
  // and never executed (a jet-on block waiting for the planner to drain must not run after
  // the reset that stopped the program). True when one was dropped.
  bool discard_pending_block();
  // Buttons pressed since the last call (the CNC side acts on them once), then forgotten.
  CncButtons take_cnc_buttons();

  // Faults (flags, control socket, sim coils all end here).
  void set_estop(bool pressed);
  void set_door_open(bool open);
  void set_pressure_drop(bool dropped);
  void set_stall(bool stalled);  // the CNC side reads stall() and stops draining its buffer
  bool stall() const;

  bool estop_pressed() const;
  bool jet_is_on() const;
  std::uint16_t alarm_code() const;

  PlcRegisters& registers();  // the server reads/writes this under its lock
  const PlcRegisters& registers() const;

 private:
  void advance(double now_s);       // the time model up to now_s
  void take_client_bits();          // sim fault coils, alarm_reset
  void take_heartbeat(double now_s);
  void take_mailbox();
  void take_cnc_buttons_from_coils();
  void latch(std::uint16_t code);
  void try_reset(double now_s);
  bool heartbeat_alive(double now_s) const;
  bool pump_running() const;
  void publish(double now_s);       // derived bits and registers from the state

  PlcConfig config_;
  PlcRegisters regs_;
  double last_s_ = 0;                 // time the model was last advanced to
  bool started_ = false;              // last_s_ is meaningful
  double pressure_01mpa_ = 0;
  double hopper_kg_ = 0;
  std::uint16_t last_heartbeat_ = 0;
  std::uint16_t heartbeat_seen_ = 0;
  bool heartbeat_armed_ = false;
  double last_heartbeat_s_ = 0;
  std::uint16_t last_seq_ = 0;        // last mailbox_seq value acted on
  std::optional<MailboxBlock> pending_;
  CncButtons buttons_;                // pressed, not yet taken by the CNC side
  std::uint32_t alarm_causes_ = 0;    // bit per alarm code still latched
  std::uint16_t alarm_code_ = modbus_map::kAlarmNone;
  CncSnapshot cnc_;
};

}  // namespace lamina::sim
