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

}  // namespace

std::string banner() {
  return fmt::format("{}GrblHAL {} ['$' or '$HELP' for help]{}", kEol, kVersion, kEol);
}

std::string status_report(const Machine& machine, std::size_t rx_free_bytes, double now_s) {
  const MachineState state = machine.state();
  std::string out = fmt::format("<{}|MPos:", state_name(state));
  const AxisValues pos = machine.position(now_s);
  for (int i = 0; i < kAxisCount; ++i) {
    if (i > 0) out += ',';
    out += coord(pos[static_cast<std::size_t>(i)]);
  }
  out += fmt::format("|Bf:{},{}", machine.free_blocks(), rx_free_bytes);
  // grblHAL shows Ln only while a block with an N number (> 0) is the current planner block.
  if (const auto n = machine.line_number(); n && *n > 0) out += fmt::format("|Ln:{}", *n);
  // FS is the real-time rate (integer, mm/min with $13=0) and the spindle speed; a waterjet
  // has no spindle speed, so 0. The rate is zero unless the axes are moving.
  double feed = 0;
  if (state == MachineState::run || state == MachineState::hold_pending)
    feed = machine.feed_mm_per_min(now_s);
  if (!(feed > 0)) feed = 0;
  out += fmt::format("|FS:{},0>{}", static_cast<std::uint64_t>(feed), kEol);
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

std::string parser_state(const ModalView& modal, bool jet_on) {
  return fmt::format("[GC:{} G54 G17 {} {} {} {} M9 T0 F{} S0]{}", motion_word(modal.motion),
                     modal.inches ? "G20" : "G21", modal.relative ? "G91" : "G90",
                     modal.inverse_time ? "G93" : "G94", jet_on ? "M3" : "M5",
                     static_cast<std::int64_t>(modal.feed), kEol);
}

std::string settings_dump() {
  // $10=511: every status report field grblHAL has (we print a subset: MPos, Bf, Ln, FS).
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
