#include "modbus_client.hpp"

#include <netdb.h>
#include <sys/socket.h>

#include <modbus/modbus.h>

#include <cerrno>
#include <chrono>
#include <cmath>
#include <mutex>
#include <thread>

#include <fmt/format.h>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

namespace lamina::drivers {
namespace {

// Exception responses: the PLC answered and refused. Everything else is the transport.
bool is_exception_response(int error) { return error >= EMBXILFUN && error <= EMBXGTAR; }

}  // namespace

std::shared_ptr<spdlog::logger> driver_logger(const std::string& name) {
  static std::mutex mutex;  // two threads creating the same logger would make spdlog throw
  std::lock_guard lock(mutex);
  if (auto existing = spdlog::get(name)) return existing;
  return spdlog::stderr_color_mt(name);
}

ModbusClient::ModbusClient(ModbusEndpoint target, std::shared_ptr<spdlog::logger> log)
    : target_(std::move(target)), log_(std::move(log)) {}

ModbusClient::~ModbusClient() { close(); }

std::string ModbusClient::where() const { return fmt::format("{}:{}", target_.host, target_.port); }

void ModbusClient::close() {
  if (!ctx_) return;
  modbus_close(ctx_);
  modbus_free(ctx_);
  ctx_ = nullptr;
}

bool ModbusClient::connect_once(std::string& error) {
  close();
  // The _pi variant resolves names and IPv6 ("plc-cell1", "fd00::7"); modbus_new_tcp takes
  // IPv4 dotted quads only and would fail a shop's PLC host name at connect time.
  const std::string service = std::to_string(target_.port);
  ctx_ = modbus_new_tcp_pi(target_.host.c_str(), service.c_str());
  if (!ctx_) {
    error = fmt::format("modbus_new_tcp_pi: {}", modbus_strerror(errno));
    return false;
  }
  const double t = std::max(0.001, target_.response_timeout_s);
  const auto sec = static_cast<std::uint32_t>(t);
  const auto usec = static_cast<std::uint32_t>(std::lround((t - sec) * 1e6));
  // libmodbus 3.1.6 also bounds the TCP connect by the response timeout.
  modbus_set_response_timeout(ctx_, sec, usec);
  modbus_set_slave(ctx_, target_.unit_id);
  if (modbus_connect(ctx_) != 0) {
    const int connect_errno = errno;
    error = modbus_strerror(connect_errno);
    // libmodbus reports a name that does not resolve as ECONNREFUSED: say what really happened.
    if (connect_errno == ECONNREFUSED) {
      addrinfo hints{};
      hints.ai_socktype = SOCK_STREAM;
      addrinfo* found = nullptr;
      if (const int gai = ::getaddrinfo(target_.host.c_str(), service.c_str(), &hints, &found); gai != 0)
        error = fmt::format("cannot resolve '{}' ({})", target_.host, ::gai_strerror(gai));
      else
        ::freeaddrinfo(found);
    }
    close();
    return false;
  }
  return true;
}

std::expected<void, LinkError> ModbusClient::call(const std::string& what, const std::function<int(_modbus*)>& op,
                                                  std::optional<std::chrono::steady_clock::time_point> give_up_at) {
  std::string last_error;
  for (int attempt = 0; attempt <= target_.max_reconnects; ++attempt) {
    if (attempt > 0) {
      if (abort_ && abort_()) break;
      if (give_up_at && std::chrono::steady_clock::now() >= *give_up_at) {
        return std::unexpected(LinkError{LinkErrorCode::timeout,
                                         fmt::format("PLC {}: {} given up: too late to be of use ({})", where(), what, last_error)});
      }
      ++reconnects_;
      log_->warn("PLC {}: {} failed ({}); reconnect {}/{}", where(), what, last_error, attempt,
                 target_.max_reconnects);
      std::this_thread::sleep_for(std::chrono::duration<double>(target_.backoff_s * attempt));
    }
    if (!ctx_ && !connect_once(last_error)) continue;
    if (op(ctx_) != -1) {
      if (attempt > 0) log_->info("PLC {}: {} succeeded after reconnect", where(), what);
      return {};
    }
    const int error = errno;
    last_error = modbus_strerror(error);
    if (is_exception_response(error))
      return std::unexpected(LinkError{LinkErrorCode::modbus_error,
                                       fmt::format("PLC {} refused {}: {}", where(), what, last_error)});
    close();  // ETIMEDOUT, EIO, ECONNRESET, EMBBADDATA…: the stream may hold a late reply
  }
  log_->error("PLC {}: {} failed after {} reconnects: {}", where(), what, target_.max_reconnects, last_error);
  return std::unexpected(LinkError{
      LinkErrorCode::modbus_error,
      fmt::format("PLC {} unreachable: {} failed after {} reconnects ({})", where(), what, target_.max_reconnects,
                  last_error)});
}

std::expected<std::vector<std::uint8_t>, LinkError> ModbusClient::read_input_bits(int address, int count) {
  std::vector<std::uint8_t> bits(static_cast<std::size_t>(count));
  auto r = call(fmt::format("reading discrete inputs {}…{}", address, address + count - 1),
                [&](modbus_t* c) { return modbus_read_input_bits(c, address, count, bits.data()); });
  if (!r) return std::unexpected(r.error());
  return bits;
}

std::expected<std::vector<std::uint16_t>, LinkError> ModbusClient::read_input_registers(int address, int count) {
  std::vector<std::uint16_t> regs(static_cast<std::size_t>(count));
  auto r = call(fmt::format("reading input registers {}…{}", address, address + count - 1),
                [&](modbus_t* c) { return modbus_read_input_registers(c, address, count, regs.data()); });
  if (!r) return std::unexpected(r.error());
  return regs;
}

std::expected<std::vector<std::uint16_t>, LinkError> ModbusClient::read_registers(int address, int count) {
  std::vector<std::uint16_t> regs(static_cast<std::size_t>(count));
  auto r = call(fmt::format("reading holding registers {}…{}", address, address + count - 1),
                [&](modbus_t* c) { return modbus_read_registers(c, address, count, regs.data()); });
  if (!r) return std::unexpected(r.error());
  return regs;
}

std::expected<void, LinkError> ModbusClient::write_bit(int address, bool on) {
  return call(fmt::format("writing coil {} = {}", address, on ? 1 : 0),
              [&](modbus_t* c) { return modbus_write_bit(c, address, on ? 1 : 0); });
}

std::expected<void, LinkError> ModbusClient::write_bit_before(int address, bool on,
                                                              std::chrono::steady_clock::time_point give_up_at) {
  return call(fmt::format("writing coil {} = {}", address, on ? 1 : 0),
              [&](modbus_t* c) { return modbus_write_bit(c, address, on ? 1 : 0); }, give_up_at);
}

std::expected<void, LinkError> ModbusClient::write_bits(int address, std::span<const std::uint8_t> bits) {
  return call(fmt::format("writing coils {}…{}", address, address + static_cast<int>(bits.size()) - 1),
              [&](modbus_t* c) { return modbus_write_bits(c, address, static_cast<int>(bits.size()), bits.data()); });
}

std::expected<void, LinkError> ModbusClient::write_register(int address, std::uint16_t value) {
  return call(fmt::format("writing holding register {} = {}", address, value),
              [&](modbus_t* c) { return modbus_write_register(c, address, value); });
}

std::expected<void, LinkError> ModbusClient::write_registers(int address, std::span<const std::uint16_t> values) {
  return call(fmt::format("writing holding registers {}…{}", address, address + static_cast<int>(values.size()) - 1),
              [&](modbus_t* c) {
                return modbus_write_registers(c, address, static_cast<int>(values.size()), values.data());
              });
}

std::unique_ptr<RegisterBus> make_modbus_bus(const ModbusEndpoint& plc, const std::string& logger_name) {
  return std::make_unique<ModbusClient>(plc, driver_logger(logger_name));
}

}  // namespace lamina::drivers
