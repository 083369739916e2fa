#pragma once
// The cell PLC's registers as CellIo and the Modbus mailbox link see them (issue 18): one small
// interface, so their sequences — pump before abrasive before jet, the heartbeat, a mailbox
// block's handshake — can be driven and checked against an in-memory PLC in tests, and the
// vendor library stays behind one implementation (ModbusClient: libmodbus TCP, bounded and
// logged reconnects). 0-based protocol addresses (drivers/src/plc_map.hpp, docs/modbus-map.md).
#include <chrono>
#include <cstdint>
#include <expected>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "lamina/drivers/link_error.hpp"
#include "lamina/drivers/modbus_endpoint.hpp"

namespace lamina::drivers {

class RegisterBus {
 public:
  virtual ~RegisterBus() = default;

  virtual std::expected<std::vector<std::uint8_t>, LinkError> read_input_bits(int address, int count) = 0;
  virtual std::expected<std::vector<std::uint16_t>, LinkError> read_input_registers(int address, int count) = 0;
  virtual std::expected<std::vector<std::uint16_t>, LinkError> read_registers(int address, int count) = 0;
  virtual std::expected<void, LinkError> write_bit(int address, bool on) = 0;
  // The same, but given up rather than done late (a button press is worth nothing late).
  virtual std::expected<void, LinkError> write_bit_before(int address, bool on,
                                                          std::chrono::steady_clock::time_point give_up_at) = 0;
  virtual std::expected<void, LinkError> write_bits(int address, std::span<const std::uint8_t> bits) = 0;
  virtual std::expected<void, LinkError> write_register(int address, std::uint16_t value) = 0;
  virtual std::expected<void, LinkError> write_registers(int address, std::span<const std::uint16_t> values) = 0;

  virtual bool connected() const = 0;
  virtual int reconnects() const = 0;      // since construction
  virtual std::string where() const = 0;   // "127.0.0.1:502"
  virtual void close() = 0;
  // Checked before every reconnect: true gives up at once (the owner is shutting down).
  virtual void set_abort(std::function<bool()> abort) = 0;
};

// The PLC over Modbus TCP (libmodbus), logging to the named logger ("cell", "modbus-link").
std::unique_ptr<RegisterBus> make_modbus_bus(const ModbusEndpoint& plc, const std::string& logger_name);

}  // namespace lamina::drivers
