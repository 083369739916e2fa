#pragma once
// What the cell's PLC inputs mean for a cut: decoding the discrete inputs and input registers
// into CellStatus (units converted here, once) and the interlock check made every poll period.
// Pure, so the rules are testable without a PLC.
#include <cstdint>
#include <optional>
#include <span>

#include "lamina/drivers/cell_io.hpp"

namespace lamina::drivers {

// inputs: discrete inputs 0…5; registers: input registers from 0 (pressure, …, alarm_code, and
// when given cnc_state and the executed-block count).
void decode_cell_inputs(std::span<const std::uint8_t> inputs, std::span<const std::uint16_t> registers,
                        CellStatus& status);

// The first interlock that stops a cut, in order of severity: e-stop, door, PLC alarm, pressure.
std::optional<CellFaultReport> check_interlocks(const CellStatus& status, const CellIoSettings& settings);

inline double mpa_from_01mpa(double value_01mpa) { return value_01mpa / 10.0; }

// Input register cnc_state (docs/modbus-map.md): 0 idle, 1 run, 2 hold pending, 3 hold, 4 alarm.
inline ControllerState cnc_state_from_register(std::uint16_t value) {
  switch (value) {
    case 0: return ControllerState::idle;
    case 1: return ControllerState::run;
    case 2: return ControllerState::hold_pending;
    case 3: return ControllerState::hold;
    case 4: return ControllerState::alarm;
    default: return ControllerState::unknown;
  }
}

}  // namespace lamina::drivers
