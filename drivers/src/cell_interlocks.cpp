#include "cell_interlocks.hpp"

#include <fmt/format.h>

#include "plc_map.hpp"

namespace lamina::drivers {
namespace pm = plc_map;

void decode_cell_inputs(std::span<const std::uint8_t> inputs, std::span<const std::uint16_t> registers,
                        CellStatus& status) {
  status.estop_ok = inputs[pm::kInputEstopOk] != 0;
  status.door_closed = inputs[pm::kInputDoorClosed] != 0;
  status.pump_ready = inputs[pm::kInputPumpReady] != 0;
  status.jet_is_on = inputs[pm::kInputJetIsOn] != 0;
  status.alarm_latched = inputs[pm::kInputAlarmLatched] != 0;
  status.cnc_jet_request = inputs[pm::kInputCncJetRequest] != 0;
  status.pressure_mpa = mpa_from_01mpa(registers[pm::kInPressure]);
  status.abrasive_g_per_min = registers[pm::kInAbrasiveFlow];
  status.alarm_code = registers[pm::kInAlarmCode];
  if (registers.size() > static_cast<std::size_t>(pm::kInCncState)) status.cnc_state = cnc_state_from_register(registers[pm::kInCncState]);
  if (registers.size() > static_cast<std::size_t>(pm::kInExecutedHigh + 1))
    status.cnc_executed_blocks = static_cast<std::uint64_t>(registers[pm::kInExecutedHigh]) << 16 |
                                 registers[pm::kInExecutedHigh + 1];
}

std::optional<CellFaultReport> check_interlocks(const CellStatus& s, const CellIoSettings& settings) {
  if (!s.estop_ok) return CellFaultReport{CellFault::estop, "e-stop pressed (estop_ok = 0)"};
  if (!s.door_closed) return CellFaultReport{CellFault::door_open, "door open (door_closed = 0)"};
  if (s.alarm_latched)
    return CellFaultReport{CellFault::plc_alarm,
                           fmt::format("PLC alarm {} ({}) latched", s.alarm_code, pm::alarm_name(s.alarm_code))};
  const double setpoint_mpa = mpa_from_01mpa(settings.pressure_setpoint_01mpa);
  const double min_mpa = settings.min_pressure_fraction * setpoint_mpa;
  if (s.pressure_mpa < min_mpa)
    return CellFaultReport{CellFault::pressure_low,
                           fmt::format("pressure {:.1f} MPa < {:.1f} MPa ({} × {:.1f} MPa)", s.pressure_mpa, min_mpa,
                                       settings.min_pressure_fraction, setpoint_mpa)};
  if (!s.pump_ready)
    return CellFaultReport{CellFault::pressure_low,
                           fmt::format("pump_ready fell: pressure {:.1f} MPa of {:.1f} MPa", s.pressure_mpa,
                                       setpoint_mpa)};
  return std::nullopt;
}

}  // namespace lamina::drivers
