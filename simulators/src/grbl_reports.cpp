#include "grbl_reports.hpp"

#include <cmath>
#include <cstdint>

#include <fmt/format.h>

namespace lamina::sim::grbl {
namespace {

// grblHAL prints coordinates with 3 decimals in mm (N_DECIMAL_COORDVALUE_MM). A value that
// rounds to zero is printed as 0.000, never -0.000 (its ftoa does not emit a sign for it).
std::string coord(double v) {
  if (std::abs(v) < 0.0005) v = 0.0;
  return fmt::format("{:.3f}", v);
}

const char* state_name(MachineState state) {
  switch (state) {
    case MachineState::idle: return "Idle";
    case MachineState::run: return "Run";
    // grblHAL prints Hold:<holding_state - 1>: 1 while decelerating, 0 once stopped.
    case MachineState::hold_pending: return "Hold:1";
    case MachineState::hold: return "Hold:0";
    case MachineState::alarm: return "Alarm";
  }
  return "Idle";
}

const char* motion_word(MotionMode mode) {
  switch (mode) {
    case MotionMode::linear: return "G1";
    case MotionMode::arc_cw: return "G2";
    case MotionMode::arc_ccw: return "G3";
    default: return "G0";  // G4 is not modal: $G keeps showing the motion mode before it
  }
}

// grblHAL's REPORT_WCO_REFRESH_* and REPORT_OVERRIDE_REFRESH_* defaults (report.c): reports
// between two WCO / Ov fields while busy (cycle, hold) and while idle.
constexpr int kWcoBusyCount = 30, kWcoIdleCount = 10;
constexpr int kOverrideBusyCount = 20, kOverrideIdleCount = 10;

// The `A:` letters as report_realtime_status writes them: spindle S (cw) or C (ccw), then
// flood F, then mist M.
std::string accessory_letters(const Accessories& a) {
  std::string out;
  if (a.spindle == SpindleCommand::cw) out += 'S';
  if (a.spindle == SpindleCommand::ccw) out += 'C';
  if (a.flood) out += 'F';
  if (a.mist) out += 'M';
  return out;
}

std::string axis_values(const AxisValues& v) {
  std::string out;
  for (int i = 0; i < kAxisCount; ++i) {
    if (i > 0) out += ',';
    out += coord(v[static_cast<std::size_t>(i)]);
  }
  return out;
}

}  // namespace

std::string banner() {
  return fmt::format("{}GrblHAL {} ['$' or '$HELP' for help]{}", kEol, kVersion, kEol);
}

void StatusReporter::restart() {
  wco_counter_ = override_counter_ = 0;
}

// report.c: WCO when sys.report.wco was set (the counter ran out in the previous report, or a
// work offset changed — here only a program end, whose system_flag_wco_change asks for it).
bool StatusReporter::wco_due(bool busy, bool idle) {
  const bool now = report_wco_;
  if (wco_counter_ > 0 && !report_wco_) {
    if (wco_counter_ > kWcoIdleCount - 1 && idle) wco_counter_ = kWcoIdleCount - 1;
    --wco_counter_;
  } else {
    wco_counter_ = busy ? kWcoBusyCount - 1 : kWcoIdleCount - 1;
  }
  return now;
}

// report.c: Ov when its counter ran out, but not beside a WCO (it follows in the next report).
bool StatusReporter::overrides_due(bool busy, bool wco_now) {
  if (override_counter_ > 0) {
    --override_counter_;
    return false;
  }
  if (wco_now) return false;
  override_counter_ = busy ? kOverrideBusyCount - 1 : kOverrideIdleCount - 1;
  return true;
}

std::string StatusReporter::report(const Machine& machine, std::size_t rx_free_bytes, double now_s) {
  MachineState state = machine.state();
  // mc_dwell plans nothing and leaves grblHAL in STATE_IDLE while it waits.
  if (state == MachineState::run && machine.dwelling()) state = MachineState::idle;
  std::string out = fmt::format("<{}|MPos:{}", state_name(state), axis_values(machine.position(now_s)));
  out += fmt::format("|Bf:{},{}", machine.free_blocks(), rx_free_bytes);
  // grblHAL shows Ln only while a block with an N number (> 0) is the current planner block.
  if (const auto n = machine.line_number(); n && *n > 0) out += fmt::format("|Ln:{}", *n);
  // FS is the real-time rate (integer, mm/min with $13=0) and the spindle speed; a waterjet
  // has no spindle speed, so 0. The rate is zero unless the axes are moving.
  double feed = 0;
  if (state == MachineState::run || state == MachineState::hold_pending) feed = machine.feed_mm_per_min(now_s);
  if (!(feed > 0)) feed = 0;
  out += fmt::format("|FS:{},0", static_cast<std::uint64_t>(feed));

  // Spindle and coolant changes (spindle_set_state, coolant_set_state) and a program end set
  // sys.report.spindle / coolant; a program end also flags the work offset (gc_execute_block).
  const Accessories acc = machine.accessories();
  if (acc != last_accessories_) report_accessories_ = true;
  if (machine.program_ends() != last_program_ends_) report_accessories_ = report_wco_ = true;
  last_accessories_ = acc;
  last_program_ends_ = machine.program_ends();

  const bool busy = state == MachineState::run || state == MachineState::hold_pending || state == MachineState::hold;
  const bool wco = wco_due(busy, state == MachineState::idle);
  const bool overrides = overrides_due(busy, wco);
  // With the Ov refresh the accessories are re-sent while one is on.
  if (overrides && acc != Accessories{}) report_accessories_ = true;
  if (wco) out += fmt::format("|WCO:{}", axis_values(AxisValues{}));  // no work offsets here
  if (overrides) out += "|Ov:100,100,100";  // feed, rapid, spindle: no override commands here
  if (report_accessories_) out += fmt::format("|A:{}", accessory_letters(acc));  // empty: all off
  // H: appears only with homing enabled ($22=1) and TLR: only once a tool length reference is
  // set (a tool setter probe): this machine has neither ($22=0, no probe), so neither appears.
  out += fmt::format(">{}", kEol);
  report_accessories_ = false;
  report_wco_ = wco_counter_ == 0;  // report.c: "Set to report on next request"
  return out;
}

std::string build_info(std::size_t planner_blocks, std::size_t rx_buffer_bytes) {
  std::string out = fmt::format("[VER:{}.{}:]{}", kVersion, kBuildDate, kEol);
  // Option letters as grblHAL builds them: V variable spindle (FS carries a speed field),
  // N line numbers, L no alarm lock at power-up. Then planner blocks, rx buffer bytes, axes
  // and tools (grblHAL's extended form always adds the last two).
  out += fmt::format("[OPT:VNL,{},{},{},0]{}", planner_blocks, rx_buffer_bytes, kAxisCount, kEol);
  out += fmt::format("[AXS:{}:", kAxisCount);
  for (char letter : kAxisLetters) out += letter;
  out += fmt::format("]{}", kEol);
  out += fmt::format("[NEWOPT:ENUMS,RT+,NOPROBE]{}", kEol);  // RT+: legacy ? ! ~ honoured
  out += fmt::format("[FIRMWARE:grblHAL]{}", kEol);
  out += fmt::format("[DRIVER:lamina-sim]{}", kEol);
  return out;
}

std::string parser_state(const ModalView& modal, const Accessories& acc) {
  const char* spindle = acc.spindle == SpindleCommand::cw ? "M3" : acc.spindle == SpindleCommand::ccw ? "M4" : "M5";
  // report_gcode_modes: M7 and/or M8 while on, M9 when both are off.
  std::string coolant = acc.mist ? "M7" : "";
  if (acc.flood) coolant += coolant.empty() ? "M8" : " M8";
  if (coolant.empty()) coolant = "M9";
  return fmt::format("[GC:{} G54 G17 {} {} {} {} {} T0 F{} S0]{}", motion_word(modal.motion),
                     modal.inches ? "G20" : "G21", modal.relative ? "G91" : "G90",
                     modal.inverse_time ? "G93" : "G94", spindle, coolant,
                     static_cast<std::int64_t>(modal.feed), kEol);
}

std::string settings_dump() {
  // $10=511: every status report field grblHAL has (those this machine can show: MPos, Bf,
  // Ln, FS, WCO, Ov, A).
  // $13=0: report in mm. $20=1: soft limits on. $21/$22=0: no hard limits, no homing.
  std::string out;
  for (const char* s : {"$0=5.0", "$1=25", "$10=511", "$11=0.010", "$12=0.002", "$13=0",
                        "$20=1", "$21=0", "$22=0", "$32=0"}) {
    out += s;
    out += kEol;
  }
  return out;
}

std::string help() {
  return fmt::format("[HLP:$$ $G $I $X ~ ! ? ctrl-x]{}", kEol);
}

}  // namespace lamina::sim::grbl
