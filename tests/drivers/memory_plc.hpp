#pragma once
// An in-memory cell PLC behind the RegisterBus seam (issue 18): CellIo's and the mailbox link's
// sequences checked without a TCP server or the simulator. It keeps the register image of
// docs/modbus-map.md, logs every write in order, and answers as the documented PLC does in the
// few ways the sequences need: the pump ramps to its set point at once, the jet opens when
// consented with the pump ready, an alarm reset clears the latch, and the block mailbox takes a
// block when a new mailbox_seq arrives (after the whole write, as the map says), acknowledging it
// at once or when the test says (hold_acks), latching alarm 3 on an overrun and 4 on a refusal.
#include <algorithm>
#include <mutex>
#include <optional>
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
  static constexpr int kCoilCncFeedHold = 4, kCoilCncCycleStart = 5, kCoilCncReset = 6;
  static constexpr int kInMailboxAck = 4, kInMailboxFree = 5, kInCncState = 7;
  static constexpr int kHoldMailboxSeq = 10, kHoldMailboxLength = 11, kHoldMailboxText = 12;
  static constexpr int kAlarmMailboxOverrun = 3, kAlarmMailboxBadBlock = 4;

  MemoryPlc() : coils_(8), inputs_(6), in_(20), hold_(112) {
    inputs_[kInputEstopOk] = 1;
    inputs_[kInputDoorClosed] = 1;
    in_[kInMailboxFree] = 8;
  }

  void set_input(int address, bool on) {
    std::lock_guard lock(m_);
    inputs_[address] = on;
  }
  void set_input_register(int address, std::uint16_t value) {
    std::lock_guard lock(m_);
    in_[address] = value;
  }
  void set_holding_register(int address, std::uint16_t value) {  // as left by an earlier supervisor
    std::lock_guard lock(m_);
    hold_[address] = value;
    last_seq_ = hold_[kHoldMailboxSeq];
  }
  void latch_alarm(int code) {
    std::lock_guard lock(m_);
    latch(code);
  }
  // Mailbox: blocks taken so far ("seq: text"), in order.
  std::vector<std::string> blocks() const {
    std::lock_guard lock(m_);
    return blocks_;
  }
  // Hold acknowledges (the CNC's queue is busy) until accept_pending(); refuse the next block.
  void hold_acks(bool hold) {
    std::lock_guard lock(m_);
    hold_acks_ = hold;
  }
  void accept_pending() {
    std::lock_guard lock(m_);
    if (pending_) in_[kInMailboxAck] = *pending_;
    pending_.reset();
  }
  // The block with this mailbox_seq is refused (bad block alarm), whenever it comes: set before
  // the job starts, so the test does not race the link's thread.
  void refuse_block(std::uint16_t seq) {
    std::lock_guard lock(m_);
    refuse_seq_ = seq;
  }
  // Reads of the input registers so far (the link polls them while it waits).
  long input_reads() const {
    std::lock_guard lock(m_);
    return input_reads_;
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
    ++input_reads_;
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
    if (address == kHoldMailboxSeq) mailbox();
    return {};
  }
  // One request (FC16): the mailbox looks at its registers after the whole write is applied.
  std::expected<void, LinkError> write_registers(int address, std::span<const std::uint16_t> values) override {
    std::lock_guard lock(m_);
    writes_.push_back(fmt::format("hold {}..{} ({} registers)", address, address + values.size() - 1, values.size()));
    for (std::size_t i = 0; i < values.size(); ++i) hold_[address + i] = values[i];
    if (address <= kHoldMailboxSeq && kHoldMailboxSeq < address + static_cast<int>(values.size())) mailbox();
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

  void mailbox() {  // under m_: a new mailbox_seq submits the block
    const std::uint16_t seq = hold_[kHoldMailboxSeq];
    if (seq == last_seq_) return;  // a retried write is harmless
    last_seq_ = seq;
    if (pending_) return latch(kAlarmMailboxOverrun);  // the new block is discarded
    const std::size_t length = hold_[kHoldMailboxLength];
    if (length > 200 || (refuse_seq_ != 0 && seq == refuse_seq_)) return latch(kAlarmMailboxBadBlock);
    std::string text;
    for (std::size_t i = 0; i < length; ++i) {
      const std::uint16_t word = hold_[kHoldMailboxText + i / 2];
      text.push_back(static_cast<char>(i % 2 == 0 ? word >> 8 : word & 0xff));
    }
    blocks_.push_back(fmt::format("{}: {}", seq, text));
    if (hold_acks_) pending_ = seq;
    else in_[kInMailboxAck] = seq;
  }
  void latch(int code) {
    inputs_[kInputAlarmLatched] = 1;
    if (in_[kInAlarmCode] == 0) in_[kInAlarmCode] = static_cast<std::uint16_t>(code);
  }

  mutable std::mutex m_;
  std::vector<std::uint8_t> coils_, inputs_;
  std::vector<std::uint16_t> in_, hold_;
  std::vector<std::string> writes_;
  std::vector<std::string> blocks_;
  std::uint16_t last_seq_ = 0;
  std::optional<std::uint16_t> pending_;
  bool hold_acks_ = false;
  std::uint16_t refuse_seq_ = 0;
  long input_reads_ = 0;
};

}  // namespace lamina::drivers::testing
