#pragma once
// A MachineLink for controllers that take their program over Modbus: one G-code block and its
// sequence number into the PLC's mailbox, then wait for the acknowledge (docs/modbus-map.md,
// "Block mailbox"). libmodbus on the link's own thread. Real-time commands go through the PLC's
// CNC coils (feed hold, cycle start, reset) and status comes from its CNC registers.
#include <memory>
#include <string>

#include "lamina/drivers/machine_link.hpp"
#include "lamina/drivers/modbus_endpoint.hpp"
#include "lamina/drivers/register_bus.hpp"

namespace lamina::drivers {

struct ModbusBlockSettings {
  ModbusEndpoint plc;
  double ack_timeout_s = 5;        // a block the CNC leaves untaken this long while idle: timeout, job stops
  double status_period_s = 0.2;
};

class ModbusBlockLink final : public MachineLink {
 public:
  // `bus`: the PLC's registers; none: Modbus TCP to settings.plc (tests give an in-memory PLC).
  explicit ModbusBlockLink(ModbusBlockSettings settings, std::unique_ptr<RegisterBus> bus = nullptr);
  ~ModbusBlockLink() override;

  std::optional<LinkError> check_lines(const std::vector<std::string>& lines, std::size_t first_index) const override;
  void start(LineSpan span, LinkCallbacks callbacks) override;
  void request(RealtimeCommand command) override;
  void stop(LinkError why) override;
  LinkProgress progress() const override;
  std::optional<LinkError> recover(double timeout_s) override;
  bool can_reset() const override { return true; }  // the PLC's reset button
  std::optional<LinkOutcome> wait(double timeout_s) override;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace lamina::drivers
