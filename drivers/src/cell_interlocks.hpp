#pragma once
// What the cell's PLC inputs mean for a cut: decoding the discrete inputs and input registers
// into CellStatus (units converted here, once) and the interlock check made every poll period.
// Pure, so the rules are testable without a PLC.
#include <cstdint>
#include <optional>
#include <span>

#include "lamina/drivers/cell_io.hpp"

namespace lamina::drivers {

// inputs: discrete inputs 0…5; registers: input registers 0…6 (pressure … alarm_code).
void decode_cell_inputs(std::span<const std::uint8_t> inputs, std::span<const std::uint16_t> registers,
                        CellStatus& status);

// The first interlock that stops a cut, in order of severity: e-stop, door, PLC alarm, pressure.
std::optional<CellFaultReport> check_interlocks(const CellStatus& status, const CellIoSettings& settings);

inline double mpa_from_01mpa(double value_01mpa) { return value_01mpa / 10.0; }

}  // namespace lamina::drivers
