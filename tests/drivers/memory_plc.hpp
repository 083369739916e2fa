#pragma once
// An in-memory cell PLC behind the RegisterBus seam (issue 18): CellIo's and the mailbox link's
// sequences checked without a TCP server or the simulator. It keeps the register image of
// docs/modbus-map.md, logs every write in order, and answers as the documented PLC does in the
// few ways the sequences need: the pump ramps to its set point at once, the jet opens when
// consented with the pump ready, an alarm reset clears the latch.
#include <algorithm>
#include <mutex>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "lamina/drivers/register_bus.hpp"

namespace lamina::drivers::testing {

class MemoryPlc final : public RegisterBus {
 public:
  // Addresses from docs/modbus-map.md, spelled out here (not the drivers' plc_map.hpp).
  static constexpr int kCoilPump = 0, kCoilAbrasive = 1, kCoilJet = 2, kCoilAlarmReset = 3;
  static constexpr int kInputEstopOk = 0, kInputDoorClosed = 1, kInputPumpReady = 2, kInputJetIsOn = 3,
                       kInputAlarmLatched = 4;
  static constexpr int kInPressure = 0, kInAlarmCode = 6;
  static constexpr int kHoldPressureSetpoint = 0, kHoldHeartbeat = 1, kHoldAbrasiveSetpoint = 2;

  MemoryPlc() : coils_(8), inputs_(6), in_(20), hold_(112) {
    inputs_[kInputEstopOk] = 1;
    inputs_[kInputDoorClosed] = 1;
  }

  void set_input(int address, bool on) {
    std::lock_guard lock(m_);
    inputs_[address] = on;
  }
  std::vector<std::string> writes() const {
    std::lock_guard lock(m_);
    return writes_;
  }
  // Index of the first write equal to `what` ("coil 0 = 1"); -1 when none.
  long first(const std::string& what) const {
    std::lock_guard lock(m_);
    const auto it = std::find(writes_.begin(), writes_.end(), what);
    return it == writes_.end() ? -1 : it - writes_.begin();
  }

  std::expected<std::vector<std::uint8_t>, LinkError> read_input_bits(int address, int count) override {
    std::lock_guard lock(m_);
    return std::vector<std::uint8_t>(inputs_.begin() + address, inputs_.begin() + address + count);
  }
  std::expected<std::vector<std::uint16_t>, LinkError> read_input_registers(int address, int count) override {
    std::lock_guard lock(m_);
    return std::vector<std::uint16_t>(in_.begin() + address, in_.begin() + address + count);
  }
  std::expected<std::vector<std::uint16_t>, LinkError> read_registers(int address, int count) override {
    std::lock_guard lock(m_);
    return std::vector<std::uint16_t>(hold_.begin() + address, hold_.begin() + address + count);
  }
  std::expected<void, LinkError> write_bit(int address, bool on) override {
    std::lock_guard lock(m_);
    writes_.push_back(fmt::format("coil {} = {}", address, on ? 1 : 0));
    coils_[address] = on;
    react();
    return {};
  }
  std::expected<void, LinkError> write_bit_before(int address, bool on, std::chrono::steady_clock::time_point) override {
    return write_bit(address, on);
  }
  std::expected<void, LinkError> write_bits(int address, std::span<const std::uint8_t> bits) override {
    for (std::size_t i = 0; i < bits.size(); ++i) (void)write_bit(address + static_cast<int>(i), bits[i] != 0);
    return {};
  }
  std::expected<void, LinkError> write_register(int address, std::uint16_t value) override {
    std::lock_guard lock(m_);
    if (address != kHoldHeartbeat)
      writes_.push_back(fmt::format("hold {} = {}", address, value));
    else if (writes_.empty() || writes_.back() != "heartbeat")  // one entry per run of beats
      writes_.push_back("heartbeat");
    hold_[address] = value;
    return {};
  }
  std::expected<void, LinkError> write_registers(int address, std::span<const std::uint16_t> values) override {
    for (std::size_t i = 0; i < values.size(); ++i) (void)write_register(address + static_cast<int>(i), values[i]);
    return {};
  }
  bool connected() const override { return true; }
  int reconnects() const override { return 0; }
  std::string where() const override { return "memory PLC"; }
  void close() override {}
  void set_abort(std::function<bool()>) override {}

 private:
  void react() {  // under m_
    inputs_[kInputPumpReady] = coils_[kCoilPump] && inputs_[kInputEstopOk];
    in_[kInPressure] = inputs_[kInputPumpReady] ? hold_[kHoldPressureSetpoint] : 0;
    if (coils_[kCoilAlarmReset]) {
      inputs_[kInputAlarmLatched] = 0, in_[kInAlarmCode] = 0;
      coils_[kCoilAlarmReset] = 0;  // a push button: the PLC clears it
    }
    inputs_[kInputJetIsOn] = coils_[kCoilJet] && inputs_[kInputPumpReady] && !inputs_[kInputAlarmLatched];
  }

  mutable std::mutex m_;
  std::vector<std::uint8_t> coils_, inputs_;
  std::vector<std::uint16_t> in_, hold_;
  std::vector<std::string> writes_;
};

}  // namespace lamina::drivers::testing
