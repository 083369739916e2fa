#pragma once
// Test-side helpers for the Modbus driver tests: the simulated cell started as a process, our
// own libmodbus client to look at the PLC independently of the code under test, a free port
// nobody listens on, and a wait helper.
#include <arpa/inet.h>
#include <modbus/modbus.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "sim_process.hpp"

namespace lamina::drivers::testing {
using namespace lamina::sim::testing;

// Addresses from docs/modbus-map.md, spelled out here so the tests read the document, not the code under test.
namespace map {
inline constexpr int kCoilPump = 0, kCoilAbrasive = 1, kCoilJet = 2;
inline constexpr int kInputPumpReady = 2, kInputJetIsOn = 3, kInputAlarmLatched = 4;
inline constexpr int kInAlarmCode = 6, kInCncState = 7;  // cnc_state: 0 idle, 1 run, 2 hold pending, 3 hold, 4 alarm
inline constexpr int kHoldHeartbeat = 1;
}  // namespace map

struct ModbusCloser {
  void operator()(modbus_t* ctx) const {
    modbus_close(ctx);
    modbus_free(ctx);
  }
};

// An independent observer of the PLC (not the code under test).
class PlcProbe {
 public:
  explicit PlcProbe(int port) : ctx_(modbus_new_tcp("127.0.0.1", port)) {
    modbus_set_response_timeout(ctx_.get(), 2, 0);
    if (modbus_connect(ctx_.get()) != 0) throw std::runtime_error("probe cannot connect to the PLC");
  }
  int coil(int address) {
    std::uint8_t bit = 0;
    if (modbus_read_bits(ctx_.get(), address, 1, &bit) != 1) return -1;
    return bit;
  }
  int input(int address) {
    std::uint8_t bit = 0;
    if (modbus_read_input_bits(ctx_.get(), address, 1, &bit) != 1) return -1;
    return bit;
  }
  int in_reg(int address) {
    std::uint16_t value = 0;
    if (modbus_read_input_registers(ctx_.get(), address, 1, &value) != 1) return -1;
    return value;
  }
  int hold(int address) {
    std::uint16_t value = 0;
    if (modbus_read_registers(ctx_.get(), address, 1, &value) != 1) return -1;
    return value;
  }

 private:
  std::unique_ptr<modbus_t, ModbusCloser> ctx_;
};

// The cell: lamina-sim with the PLC on a free port, a fast pump ramp and a 500 ms watchdog.
struct SimCell {
  explicit SimCell(std::vector<std::string> extra = {})
      : sim([&] {
          std::vector<std::string> args{"--link", dir.file("cnc"), "--modbus", "127.0.0.1:0", "--control",
                                        "127.0.0.1:0", "--log", dir.file("exec.jsonl"), "--pressure-ramp", "0.2",
                                        "--heartbeat-timeout", "500"};
          args.insert(args.end(), extra.begin(), extra.end());
          return args;
        }()) {}
  TempDir dir;  // before sim: it must outlive the process
  SimProcess sim;
  std::string log() const { return dir.file("exec.jsonl"); }
};

// A loopback port with nobody listening (bound, read, closed: the kernel refuses connections).
inline int unused_port() {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = 0;
  ::inet_pton(AF_INET, "127.0.0.1", &addr.sin_addr);
  ::bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr);
  socklen_t len = sizeof addr;
  ::getsockname(fd, reinterpret_cast<sockaddr*>(&addr), &len);
  ::close(fd);
  return ntohs(addr.sin_port);
}

inline bool eventually(const std::function<bool()>& ready, double wait_s) {
  const auto t0 = std::chrono::steady_clock::now();
  while (seconds_since(t0) < wait_s) {
    if (ready()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return ready();
}

}  // namespace lamina::drivers::testing
