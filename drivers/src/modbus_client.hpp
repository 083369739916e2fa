#pragma once
// One libmodbus TCP connection with bounded, logged reconnects: the RegisterBus of CellIo and
// ModbusBlockLink (register_bus.hpp). Not thread-safe: each owner uses it from its own thread only.
//
// Transport failures (ETIMEDOUT, EIO, ECONNRESET, EPIPE, ECONNREFUSED, EMBBADDATA, …) close the
// socket and the request is retried on a new connection, up to max_reconnects times with a short
// backoff. Every request here is safe to repeat: coil and register writes are idempotent, and the
// PLC ignores a rewritten mailbox sequence number. A Modbus exception response (the PLC refused
// the request) is returned at once: reconnecting would not change the answer.
#include <cstdint>
#include <expected>
#include <chrono>
#include <functional>
#include <optional>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "lamina/drivers/link_error.hpp"
#include "lamina/drivers/modbus_endpoint.hpp"
#include "lamina/drivers/register_bus.hpp"

struct _modbus;  // libmodbus's modbus_t; its header stays in the .cpp

namespace spdlog {
class logger;
}

namespace lamina::drivers {


// Named logger shared by every instance ("cell", "modbus-link"), created on first use.
std::shared_ptr<spdlog::logger> driver_logger(const std::string& name);

class ModbusClient final : public RegisterBus {
 public:
  ModbusClient(ModbusEndpoint target, std::shared_ptr<spdlog::logger> log);
  ~ModbusClient();
  ModbusClient(const ModbusClient&) = delete;
  ModbusClient& operator=(const ModbusClient&) = delete;

  std::expected<std::vector<std::uint8_t>, LinkError> read_input_bits(int address, int count) override;
  std::expected<std::vector<std::uint16_t>, LinkError> read_input_registers(int address, int count) override;
  std::expected<std::vector<std::uint16_t>, LinkError> read_registers(int address, int count) override;
  std::expected<void, LinkError> write_bit(int address, bool on) override;
  // The same, but no reconnect is started after `give_up_at`: for a request that is worth
  // nothing late (a button press), an error instead of a late success.
  std::expected<void, LinkError> write_bit_before(int address, bool on, std::chrono::steady_clock::time_point give_up_at) override;
  std::expected<void, LinkError> write_bits(int address, std::span<const std::uint8_t> bits) override;
  std::expected<void, LinkError> write_register(int address, std::uint16_t value) override;
  std::expected<void, LinkError> write_registers(int address, std::span<const std::uint16_t> values) override;

  bool connected() const override { return ctx_ != nullptr; }
  int reconnects() const override { return reconnects_; }  // since construction
  std::string where() const override;             // "127.0.0.1:502"
  void close() override;
  // Checked before every reconnect: true gives up at once (the owner is shutting down).
  void set_abort(std::function<bool()> abort) override { abort_ = std::move(abort); }

 private:
  // Runs op on a connected context; the retry policy above. `what` names the request in errors.
  std::expected<void, LinkError> call(const std::string& what, const std::function<int(_modbus*)>& op,
                                      std::optional<std::chrono::steady_clock::time_point> give_up_at = {});
  bool connect_once(std::string& error);

  ModbusEndpoint target_;
  std::shared_ptr<spdlog::logger> log_;
  _modbus* ctx_ = nullptr;
  int reconnects_ = 0;
  std::function<bool()> abort_;
};

}  // namespace lamina::drivers
