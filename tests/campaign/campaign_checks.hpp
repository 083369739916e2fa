#pragma once
// The fault campaign's oracle (docs/reliability.md): what lamina-sim's execution log must show
// after any fault, judged from the log and the program text alone — written from the shop's
// rules, not from the daemon's code.
//
//  - Every contour is cut once: a contour whose cutting moves all ran with the water flowing is
//    never cut again; a contour a fault cut short is cut again from its start (the documented
//    resume rule); on a finished sheet no contour is left uncut or partly dry.
//  - The jet is never on while the machine stands still (hold, idle, alarm) for longer than a
//    limit in wall-clock time: a pierce dwell is the program's, not a standstill.
#include <cstddef>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace lamina::campaign {

// lamina-sim's log (docs/simulator.md), the records these checks read.
struct Block {
  std::string line;
  bool completed = true;
  bool jet_commanded = false;  // the CNC's M-code while it ran
  bool moved = false;
  double t_start_s = 0, t_end_s = 0;  // simulated seconds
};
struct Change {
  double t_s = 0;
  bool flowing = false;  // "jet" events: the water as the part feels it (M-code and the PLC's consent)
  std::string state;     // "state" events: idle, run, hold_pending, hold, alarm
};
struct ScaleChange {
  double t_s = 0;
  double scale = 1;  // simulated seconds per wall second from t_s on
};
struct MachineLog {
  std::vector<Block> blocks;
  std::vector<Change> jet;     // in time order
  std::vector<Change> states;  // in time order
  double initial_scale = 1;    // the "start" event's time_scale
  std::vector<ScaleChange> scales;  // "time_scale" events (control `time-scale K`)
  // Wall-clock seconds between two simulated instants, under the scales in force.
  double wall_between(double a_s, double b_s) const;
};
MachineLog parse_machine_log(const std::vector<nlohmann::json>& records);

struct ContourCheck {
  std::vector<std::string> violations;
  std::size_t contours = 0;
  std::size_t finished = 0;    // contours whose every cutting move ran with the water on, in one pass
  std::size_t cut_again = 0;   // contours a fault cut short and a resume cut again from the start
  std::size_t passes = 0;      // runs through the program: the first, and one per resume
};
// `sheet_complete`: the sheet was reported done, so every contour must be finished.
ContourCheck check_contours_cut_once(const std::vector<std::string>& program, const MachineLog& log,
                                     bool sheet_complete);

struct JetCheck {
  std::vector<std::string> violations;
  std::size_t standstills_with_jet = 0;  // times the water flowed on a machine that stopped
  double worst_wall_s = 0;               // the longest of them, wall-clock
  std::size_t restarts_in_kerf = 0;      // the jet opened on a standing machine that then moved on
  double worst_restart_wall_s = 0;
};
// A machine that stops with the water on must have it off within `limit_wall_s`. The one
// standstill with the water on by design is a resume from a hold: the jet re-opens in the kerf
// and the motion follows after the stabilisation time ([cell] jet_restart_s): allowed up to
// `restart_wall_s` when motion follows; a jet opened on a standing machine and closed again
// without moving is held to `limit_wall_s` from the moment it opened.
JetCheck check_jet_off_at_standstill(const MachineLog& log, double limit_wall_s, double restart_wall_s);

}  // namespace lamina::campaign
