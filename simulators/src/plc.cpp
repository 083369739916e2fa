#include "plc.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace lamina::sim {
namespace mm = modbus_map;
namespace {

std::uint32_t alarm_bit(std::uint16_t code) { return 1u << code; }

// int32 in two registers, high word first (docs/modbus-map.md, "32-bit values").
void put_u32(std::vector<std::uint16_t>& regs, int high_address, std::uint32_t value) {
  regs[high_address] = static_cast<std::uint16_t>(value >> 16);
  regs[high_address + 1] = static_cast<std::uint16_t>(value & 0xFFFFu);
}

std::int32_t to_int32_milli(double value) {
  const double scaled = std::round(value * 1000.0);
  constexpr double lo = std::numeric_limits<std::int32_t>::min();
  constexpr double hi = std::numeric_limits<std::int32_t>::max();
  if (!(scaled >= lo)) return std::numeric_limits<std::int32_t>::min();  // also NaN
  if (scaled > hi) return std::numeric_limits<std::int32_t>::max();
  return static_cast<std::int32_t>(scaled);
}

}  // namespace

Plc::Plc(PlcConfig config) : config_(config), hopper_kg_(config.hopper_kg) {
  regs_.holding[mm::kHoldPressureSetpoint] = config_.default_setpoint_01mpa;
  regs_.holding[mm::kHoldAbrasiveSetpoint] = config_.default_abrasive_g_per_min;
  publish(0);
}

void Plc::after_client_write(double now_s) {
  // Time first: a heartbeat that arrives after the timeout must still find the alarm latched.
  advance(now_s);
  take_client_bits();
  take_heartbeat(now_s);
  take_mailbox();
  take_cnc_buttons_from_coils();
  // The reset comes after the heartbeat so a write carrying both a heartbeat and the reset works.
  if (regs_.coils[mm::kCoilAlarmReset]) {
    regs_.coils[mm::kCoilAlarmReset] = 0;  // self-clearing: reads back 0
    try_reset(now_s);
  }
  publish(now_s);
}

void Plc::tick(double now_s, const CncSnapshot& cnc) {
  cnc_ = cnc;
  advance(now_s);
  take_heartbeat(now_s);
  publish(now_s);
}

std::optional<MailboxBlock> Plc::pending_block() const { return pending_; }

void Plc::accept_block(std::uint16_t seq) {
  if (!pending_ || pending_->seq != seq) return;
  pending_.reset();
  regs_.input_registers[mm::kInMailboxAck] = seq;
}

void Plc::refuse_block(std::uint16_t seq) {
  if (!pending_ || pending_->seq != seq) return;
  pending_.reset();
  latch(mm::kAlarmMailboxBadBlock);
  publish(last_s_);
}

bool Plc::discard_pending_block() {
  if (!pending_) return false;
  pending_.reset();
  return true;
}

CncButtons Plc::take_cnc_buttons() { return std::exchange(buttons_, CncButtons{}); }

void Plc::take_cnc_buttons_from_coils() {
  // Push buttons: a press is remembered until the CNC side takes it, and the coil reads 0 again
  // at once (like alarm_reset), so pressing twice needs no release write in between.
  auto press = [&](int address, bool& pressed) {
    if (!regs_.coils[address]) return;
    regs_.coils[address] = 0;
    pressed = true;
  };
  CncButtons now;
  press(mm::kCoilCncFeedHold, now.feed_hold);
  press(mm::kCoilCncCycleStart, now.cycle_start);
  press(mm::kCoilCncReset, now.reset);
  if (now.reset) {
    // The CNC side takes the presses of one scan together, reset first. A hold or cycle start
    // pressed in an earlier write is spent by this reset, not replayed on the reset machine.
    buttons_ = now;
  } else {
    buttons_.feed_hold = buttons_.feed_hold || now.feed_hold;
    buttons_.cycle_start = buttons_.cycle_start || now.cycle_start;
  }
}

void Plc::set_estop(bool pressed) {
  regs_.coils[mm::kCoilSimEstop] = pressed ? 1 : 0;
  take_client_bits();
  publish(last_s_);
}

void Plc::set_door_open(bool open) {
  regs_.coils[mm::kCoilSimDoorOpen] = open ? 1 : 0;
  publish(last_s_);
}

void Plc::set_pressure_drop(bool dropped) {
  regs_.coils[mm::kCoilSimPressureDrop] = dropped ? 1 : 0;
  publish(last_s_);
}

void Plc::set_stall(bool stalled) { regs_.coils[mm::kCoilSimStall] = stalled ? 1 : 0; }
bool Plc::stall() const { return regs_.coils[mm::kCoilSimStall] != 0; }
bool Plc::estop_pressed() const { return regs_.coils[mm::kCoilSimEstop] != 0; }
bool Plc::jet_is_on() const { return regs_.inputs[mm::kInputJetIsOn] != 0; }
std::uint16_t Plc::alarm_code() const { return alarm_code_; }
PlcRegisters& Plc::registers() { return regs_; }
const PlcRegisters& Plc::registers() const { return regs_; }

bool Plc::pump_running() const {
  return regs_.coils[mm::kCoilPumpEnable] && !estop_pressed() && !(alarm_causes_ & alarm_bit(mm::kAlarmEstop));
}

void Plc::advance(double now_s) {
  if (!started_) {
    started_ = true;
    last_s_ = now_s;
  }
  const double dt = std::max(0.0, now_s - last_s_);
  last_s_ = std::max(last_s_, now_s);

  // Pressure: linear towards the target at set point / ramp time per second.
  const double setpoint = regs_.holding[mm::kHoldPressureSetpoint];
  double target = 0;
  if (pump_running())
    target = regs_.coils[mm::kCoilSimPressureDrop] ? setpoint * config_.pressure_drop_fraction : setpoint;
  if (config_.pressure_ramp_s <= 0) {
    pressure_01mpa_ = target;
  } else {
    const double step = std::max(setpoint, pressure_01mpa_) / config_.pressure_ramp_s * dt;
    if (pressure_01mpa_ < target) pressure_01mpa_ = std::min(target, pressure_01mpa_ + step);
    else pressure_01mpa_ = std::max(target, pressure_01mpa_ - step);
  }

  // Abrasive: the flow over dt is constant (it changes only at writes, which advance first).
  const bool feeding = regs_.coils[mm::kCoilAbrasiveEnable] && !estop_pressed() &&
                       !(alarm_causes_ & alarm_bit(mm::kAlarmEstop)) && hopper_kg_ > 0;
  if (feeding)
    hopper_kg_ = std::max(0.0, hopper_kg_ - regs_.holding[mm::kHoldAbrasiveSetpoint] * dt / 60.0 / 1000.0);

  if (estop_pressed()) latch(mm::kAlarmEstop);
  if (heartbeat_armed_ && now_s - last_heartbeat_s_ > config_.heartbeat_timeout_s &&
      !(alarm_causes_ & alarm_bit(mm::kAlarmHeartbeat))) {
    latch(mm::kAlarmHeartbeat);
    // Nobody supervises the cut any more: the jet goes off (the jet logic) and a CNC in its
    // cycle (moving, or its jet M-code on: a pierce dwell) is held through its feed-hold input,
    // so it does not run its queue on dry — the contours it would have moved through uncut
    // would then count as executed. An idle CNC is left alone: held, it would refuse the next
    // sheet (controller_held), and between sheets the heartbeat stops by design.
    if (cnc_.state == 1 || cnc_.jet_request) buttons_.feed_hold = true;
  }
}

void Plc::take_client_bits() {
  for (int a = 0; a < mm::kCoilSimEnd; ++a) regs_.coils[a] = regs_.coils[a] ? 1 : 0;
  if (estop_pressed()) latch(mm::kAlarmEstop);
}

void Plc::take_heartbeat(double now_s) {
  const std::uint16_t value = regs_.holding[mm::kHoldHeartbeat];
  if (value == last_heartbeat_) return;
  last_heartbeat_ = value;
  ++heartbeat_seen_;
  last_heartbeat_s_ = now_s;
  if (config_.heartbeat_timeout_s > 0) heartbeat_armed_ = true;
}

void Plc::take_mailbox() {
  const std::uint16_t seq = regs_.holding[mm::kHoldMailboxSeq];
  if (seq == last_seq_) return;  // a retried write of the same block does nothing
  last_seq_ = seq;
  if (pending_) {
    latch(mm::kAlarmMailboxOverrun);  // the earlier block stays pending; this one is dropped
    return;
  }
  const int length = regs_.holding[mm::kHoldMailboxLength];
  if (length > mm::kMailboxMaxChars) {
    latch(mm::kAlarmMailboxBadBlock);
    return;
  }
  std::string text;
  text.reserve(length);
  for (int i = 0; i < length; ++i) {
    const std::uint16_t word = regs_.holding[mm::kHoldMailboxText + i / 2];
    const auto c = static_cast<unsigned char>(i % 2 == 0 ? word >> 8 : word & 0xFFu);
    // One block is one line: a line break or NUL inside would split or truncate it in the CNC.
    if ((c < 0x20 && c != '\t') || c == 0x7F) {
      latch(mm::kAlarmMailboxBadBlock);
      return;
    }
    text.push_back(static_cast<char>(c));
  }
  pending_ = MailboxBlock{seq, std::move(text)};
}

void Plc::latch(std::uint16_t code) {
  if (alarm_causes_ == 0) alarm_code_ = code;
  alarm_causes_ |= alarm_bit(code);
}

void Plc::try_reset(double now_s) {
  if (!estop_pressed()) alarm_causes_ &= ~alarm_bit(mm::kAlarmEstop);
  if (heartbeat_alive(now_s)) alarm_causes_ &= ~alarm_bit(mm::kAlarmHeartbeat);
  alarm_causes_ &= ~(alarm_bit(mm::kAlarmMailboxOverrun) | alarm_bit(mm::kAlarmMailboxBadBlock));
  if (alarm_causes_ == 0) {
    alarm_code_ = mm::kAlarmNone;
  } else if (!(alarm_causes_ & alarm_bit(alarm_code_))) {
    for (std::uint16_t c = 1; c < 32; ++c)
      if (alarm_causes_ & alarm_bit(c)) {
        alarm_code_ = c;
        break;
      }
  }
}

bool Plc::heartbeat_alive(double now_s) const {
  return !heartbeat_armed_ || now_s - last_heartbeat_s_ <= config_.heartbeat_timeout_s;
}

void Plc::publish(double now_s) {
  const double setpoint = regs_.holding[mm::kHoldPressureSetpoint];
  const bool estop_ok = !estop_pressed();
  const bool door_closed = regs_.coils[mm::kCoilSimDoorOpen] == 0;
  const bool pump_ready = pump_running() && setpoint > 0 &&
                          pressure_01mpa_ >= config_.pressure_ready_fraction * setpoint - 1e-9;
  const bool alarm_latched = alarm_causes_ != 0;
  const bool jet = regs_.coils[mm::kCoilJetOn] && pump_ready && door_closed && estop_ok && !alarm_latched &&
                   heartbeat_alive(now_s);
  const bool feeding = regs_.coils[mm::kCoilAbrasiveEnable] && estop_ok &&
                       !(alarm_causes_ & alarm_bit(mm::kAlarmEstop)) && hopper_kg_ > 0;

  auto& in = regs_.inputs;
  in[mm::kInputEstopOk] = estop_ok;
  in[mm::kInputDoorClosed] = door_closed;
  in[mm::kInputPumpReady] = pump_ready;
  in[mm::kInputJetIsOn] = jet;
  in[mm::kInputAlarmLatched] = alarm_latched;
  in[mm::kInputCncJetRequest] = cnc_.jet_request;

  auto& ir = regs_.input_registers;
  ir[mm::kInPressure] = static_cast<std::uint16_t>(std::lround(std::clamp(pressure_01mpa_, 0.0, 65535.0)));
  ir[mm::kInAbrasiveFlow] = feeding ? regs_.holding[mm::kHoldAbrasiveSetpoint] : 0;
  ir[mm::kInHopperLevel] = static_cast<std::uint16_t>(std::lround(std::clamp(hopper_kg_ * 10.0, 0.0, 65535.0)));
  ir[mm::kInHeartbeatSeen] = heartbeat_seen_;
  ir[mm::kInMailboxFree] = static_cast<std::uint16_t>(std::min<std::size_t>(cnc_.free_blocks, 65535));
  ir[mm::kInAlarmCode] = alarm_code_;
  ir[mm::kInCncState] = static_cast<std::uint16_t>(cnc_.state);
  put_u32(ir, mm::kInExecutedHigh, static_cast<std::uint32_t>(cnc_.executed_blocks));  // wraps at 2^32
  for (int axis = 0; axis < 5; ++axis)
    put_u32(ir, mm::kInPositionFirst + 2 * axis, static_cast<std::uint32_t>(to_int32_milli(cnc_.position[axis])));
}

}  // namespace lamina::sim
