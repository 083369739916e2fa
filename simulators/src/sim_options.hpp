#pragma once
// Everything lamina-sim is told on its command line and in its --machine TOML file.
#include <cstdint>
#include <optional>
#include <string>

#include "grbl_protocol.hpp"
#include "host_pacer.hpp"
#include "jet_head.hpp"
#include "jet_physics.hpp"
#include "machine.hpp"
#include "plc.hpp"
#include "xonxoff_protocol.hpp"

namespace lamina::sim {

// Faults scheduled from the command line. Times are simulated seconds since start (the same
// clock as the execution log's t_start / t_end); lines count lines the CNC received.
struct FaultSchedule {
  std::optional<std::uint64_t> unplug_at_line;
  std::optional<double> unplug_at_s;
  std::optional<double> replug_after_ms;  // a new PTY / listener this long after an unplug
  std::optional<double> estop_at_s;
  std::optional<double> pressure_drop_at_s;
  std::optional<double> stall_at_s;
  double stall_ms = 0;
  double garble_probability = 0;
  std::uint64_t garble_seed = 1;
};

// What the controller does when a client opens its port. Boards differ, and a host must cope
// with each: a classic Grbl on an Arduino reboots when DTR rises (motion stops, queue lost,
// banner); a grblHAL controller on native USB or Ethernet does not notice the open at all — it
// prints its banner at boot and after a reset only (report_init_message), so a host that opens
// the port later hears nothing until it asks.
enum class OnOpen {
  banner,  // the banner, nothing else changes (a board whose USB bridge replays it)
  reset,   // a reset as DTR gives a classic Grbl: motion stops, queue and buffer flushed, banner
  quiet,   // nothing (the default, native-USB grblHAL): it keeps running and says nothing until asked
};

struct SimOptions {
  std::string personality = "grbl";  // grbl | xonxoff
  std::string link_path;             // PTY symlink
  std::string tcp_address;           // HOST:PORT
  std::string modbus_address;        // HOST:PORT
  std::string control_address;       // HOST:PORT
  std::string log_path;
  double baud = 115200;
  double time_scale = 1;
  bool pace_to_host = false;  // --pace-to-host (host_pacer.hpp): real time while the host falls behind
  OnOpen on_open = OnOpen::quiet;
  MachineConfig machine;
  // The head (head_* keys of the machine file): with it, the execution log says where the jet's
  // tip and axis are at the end of every block.
  std::optional<HeadGeometry> head;
  JetPhysics jet;  // jet_* keys: the kerf this machine's jet really leaves (--measure-coupon)
  GrblParams grbl;
  XonXoffParams xonxoff;
  PlcConfig plc;
  FaultSchedule faults;
};

// Throws std::runtime_error with the file, line and key for a malformed or unknown entry.
void apply_machine_file(const std::string& path, SimOptions& options);

}  // namespace lamina::sim
