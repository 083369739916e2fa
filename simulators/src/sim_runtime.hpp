#pragma once
// The simulator process: one loop that paces bytes between the CNC port and the controller
// personality, runs the machine's time model, ticks the PLC (whose Modbus server has its own
// thread), applies scheduled and requested faults, answers the control socket and writes the
// execution log. Wall time paces the link; simulated time (wall × time scale) runs the machine.
#include <atomic>
#include <chrono>
#include <memory>
#include <mutex>
#include <optional>
#include <random>
#include <string>

#include <nlohmann/json.hpp>

#include "byte_pacer.hpp"
#include "cnc_port.hpp"
#include "cnc_protocol.hpp"
#include "control_socket.hpp"
#include "exec_log.hpp"
#include "host_pacer.hpp"
#include "machine.hpp"
#include "modbus_server.hpp"
#include "plc.hpp"
#include "sim_clock.hpp"
#include "sim_options.hpp"

namespace lamina::sim {

class SimRuntime {
 public:
  explicit SimRuntime(SimOptions options);  // opens ports and servers; throws on failure
  ~SimRuntime();

  // {"ready":true,"personality":…,"link":…,"tcp_port":…,"modbus_port":…,"control_port":…}
  nlohmann::json ready_info() const;
  void run(const std::atomic<bool>& stop);

 private:
  double wall_s() const { return clock_.wall_s(); }
  double sim_s() const { return clock_.sim_s(); }
  void step();
  void move_bytes_in(double wall, double now);
  void move_bytes_out(double wall);
  void discard_output();
  void oversleep(double now);
  void log_jet_and_state(double now);
  void log_realtime_byte(std::uint8_t byte, double now);
  void tick_plc(double now);
  void reset_cnc(double now, const char* source);  // takes the PLC lock
  void reset_cnc_locked(double now);               // the caller holds it
  void apply_schedule(double wall, double now);
  void unplug(double now, const std::string& why);
  std::string handle_command(const std::string& line);
  void pace_to_host(double now);            // after the controller took its lines: the clock's next rate
  double sim_at_with_knee(double wall);     // the clock at `wall`, a pacing knee passed on the way applied
  void change_scale(double now, double to, const char* reason);  // logged; the PLC's watchdog follows
  std::optional<std::string> clock_or_network_command(const std::string& verb, const std::string& arg, double now);
  nlohmann::json status_json() const;

  SimOptions options_;
  SimClock clock_;
  Machine machine_;
  std::unique_ptr<CncProtocol> protocol_;
  std::unique_ptr<CncPort> port_;
  BytePacer rx_pacer_;
  BytePacer tx_pacer_;
  std::string tx_pending_;
  ExecLog log_;
  std::mutex plc_mutex_;
  Plc plc_;
  std::unique_ptr<ModbusServer> modbus_;
  std::unique_ptr<ControlSocket> control_;
  std::mt19937_64 garble_rng_;
  std::uint64_t bytes_garbled_ = 0;
  bool estop_applied_ = false;
  bool unplugged_by_fault_ = false;
  std::optional<double> replug_at_wall_;
  std::optional<double> stall_until_wall_;
  std::optional<double> lag_pending_s_;  // control `lag MS`: sleep once, after the next bytes read
  bool schedule_unplug_done_ = false, schedule_estop_done_ = false, schedule_pressure_done_ = false,
       schedule_stall_done_ = false;
  std::uint64_t unplugs_ = 0;
  bool jet_flowing_ = false;                 // as last logged ("jet" events)
  std::string logged_state_ = "idle";        // as last logged ("state" events)
  HostPacer pacer_;
  double scale_asked_ = 1;                 // --time-scale or control `time-scale K`: the pacer's ceiling
  std::optional<PaceDecision> pace_knee_;  // slow down at this simulated instant
  std::uint64_t line_ends_in_ = 0;  // LF bytes that reached the controller (for --unplug-at-line)
};

}  // namespace lamina::sim
