#pragma once
// Modbus TCP server for the PLC (libmodbus), on its own thread because libmodbus blocks.
// Loopback only. Serves any number of clients (select over the listening socket and the
// clients); a client that sends garbage or a partial frame is dropped, never stalls the others.
// Every request is answered from / written into Plc::registers() under `mutex`, and
// Plc::after_client_write runs under the same lock after a write.
#include <functional>
#include <memory>
#include <mutex>
#include <string>

#include "plc.hpp"

namespace lamina::sim {

class ModbusServer {
 public:
  // Binds host:port (port 0 picks a free one, see port()). Throws std::runtime_error naming
  // the address and errno when it cannot listen; refuses a host that is not loopback.
  ModbusServer(std::string host, int port, Plc& plc, std::mutex& mutex,
               std::function<double()> now_s);
  ~ModbusServer();  // stops the thread and closes every socket
  ModbusServer(const ModbusServer&) = delete;
  ModbusServer& operator=(const ModbusServer&) = delete;

  int port() const;
  std::size_t requests_served() const;
  // Off the network: every client dropped, new connections left unanswered and closed unread
  // when it is back.
  void set_network_up(bool up);
  bool network_up() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace lamina::sim
