// The PLC's Modbus TCP server in-process on port 0, talked to as clients would: libmodbus,
// a raw socket sending garbage, and once a peer nobody here wrote (Debian's mbpoll).
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <modbus/modbus.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <mutex>
#include <regex>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include <fmt/format.h>

#include "modbus_server.hpp"

namespace lamina::sim {
namespace {
namespace mm = modbus_map;
using Clock = std::chrono::steady_clock;

struct ModbusCloser {
  void operator()(modbus_t* ctx) const {
    modbus_close(ctx);
    modbus_free(ctx);
  }
};
using Client = std::unique_ptr<modbus_t, ModbusCloser>;

Client connect_client(int port) {
  Client c(modbus_new_tcp("127.0.0.1", port));
  if (!c) throw std::runtime_error("modbus_new_tcp failed");
  modbus_set_response_timeout(c.get(), 2, 0);
  if (modbus_connect(c.get()) != 0)
    throw std::runtime_error(fmt::format("cannot connect to port {}: {}", port, modbus_strerror(errno)));
  return c;
}

struct Cell {
  Plc plc{PlcConfig{}};
  std::mutex mutex;
  Clock::time_point t0 = Clock::now();
  ModbusServer server{"127.0.0.1", 0, plc, mutex,
                      [this] { return std::chrono::duration<double>(Clock::now() - t0).count(); }};

  template <class F>
  auto locked(F f) {
    std::lock_guard lock(mutex);
    return f(plc);
  }
};

TEST(ModbusServer, PortZeroPicksAFreePort) {
  Cell cell;
  EXPECT_GT(cell.server.port(), 0);
  EXPECT_NE(cell.server.port(), 502);
}

TEST(ModbusServer, RefusesANonLoopbackHostAndABusyPort) {
  Plc plc{PlcConfig{}};
  std::mutex mutex;
  auto clock = [] { return 0.0; };
  EXPECT_THROW(ModbusServer("0.0.0.0", 0, plc, mutex, clock), std::runtime_error);
  EXPECT_THROW(ModbusServer("192.168.1.10", 0, plc, mutex, clock), std::runtime_error);
  EXPECT_THROW(ModbusServer("example.org", 0, plc, mutex, clock), std::runtime_error);
  ModbusServer first("127.0.0.1", 0, plc, mutex, clock);
  try {
    ModbusServer second("127.0.0.1", first.port(), plc, mutex, clock);
    ADD_FAILURE() << "a second server on the same port started";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(std::to_string(first.port())), std::string::npos) << e.what();
  }
  ModbusServer by_name("localhost", 0, plc, mutex, clock);
  EXPECT_GT(by_name.port(), 0);
}

TEST(ModbusServer, ReadsAndWritesEveryArea) {
  Cell cell;
  auto c = connect_client(cell.server.port());

  // Coils: single and multiple writes, read back; the fault coils at 100.
  ASSERT_EQ(modbus_write_bit(c.get(), mm::kCoilPumpEnable, 1), 1);
  const std::uint8_t two[] = {1, 1};
  ASSERT_EQ(modbus_write_bits(c.get(), mm::kCoilAbrasiveEnable, 2, two), 2);
  std::uint8_t coils[4] = {};
  ASSERT_EQ(modbus_read_bits(c.get(), 0, 4, coils), 4);
  EXPECT_EQ(coils[mm::kCoilPumpEnable], 1);
  EXPECT_EQ(coils[mm::kCoilAbrasiveEnable], 1);
  EXPECT_EQ(coils[mm::kCoilJetOn], 1);
  EXPECT_EQ(coils[mm::kCoilAlarmReset], 0);
  ASSERT_EQ(modbus_write_bit(c.get(), mm::kCoilSimDoorOpen, 1), 1);
  std::uint8_t faults[4] = {};
  ASSERT_EQ(modbus_read_bits(c.get(), mm::kCoilSimEstop, 4, faults), 4);
  EXPECT_EQ(faults[1], 1);
  EXPECT_TRUE(cell.locked([](Plc& p) { return p.registers().coils[mm::kCoilPumpEnable] == 1; }));

  // Discrete inputs follow at once (the PLC runs after every write).
  std::uint8_t inputs[mm::kInputCount] = {};
  ASSERT_EQ(modbus_read_input_bits(c.get(), 0, mm::kInputCount, inputs), mm::kInputCount);
  EXPECT_EQ(inputs[mm::kInputEstopOk], 1);
  EXPECT_EQ(inputs[mm::kInputDoorClosed], 0);
  EXPECT_EQ(inputs[mm::kInputJetIsOn], 0);

  // Holding registers: single, multiple, and the combined write-and-read.
  ASSERT_EQ(modbus_write_register(c.get(), mm::kHoldPressureSetpoint, 3000), 1);
  const std::uint16_t beat_and_abrasive[] = {7, 420};
  ASSERT_EQ(modbus_write_registers(c.get(), mm::kHoldHeartbeat, 2, beat_and_abrasive), 2);
  std::uint16_t hold[3] = {};
  ASSERT_EQ(modbus_read_registers(c.get(), 0, 3, hold), 3);
  EXPECT_EQ(hold[0], 3000);
  EXPECT_EQ(hold[1], 7);
  EXPECT_EQ(hold[2], 420);
  const std::uint16_t beat = 8;
  std::uint16_t back[3] = {};
  ASSERT_EQ(modbus_write_and_read_registers(c.get(), mm::kHoldHeartbeat, 1, &beat, 0, 3, back), 3);
  EXPECT_EQ(back[1], 8);

  // Input registers: the whole block.
  cell.locked([](Plc& p) {
    CncSnapshot s;
    s.state = 1;
    s.position[2] = -12.5;
    s.free_blocks = 9;
    p.tick(0.1, s);
    return 0;
  });
  std::uint16_t in[mm::kInCount] = {};
  ASSERT_EQ(modbus_read_input_registers(c.get(), 0, mm::kInCount, in), mm::kInCount);
  EXPECT_EQ(in[mm::kInHopperLevel], 500);
  EXPECT_EQ(in[mm::kInHeartbeatSeen], 2);  // 7 then 8
  EXPECT_EQ(in[mm::kInAbrasiveFlow], 420);
  EXPECT_EQ(in[mm::kInMailboxFree], 9);
  EXPECT_EQ(in[mm::kInCncState], 1);
  EXPECT_EQ(static_cast<std::int32_t>((in[mm::kInPositionZHigh] << 16) | in[mm::kInPositionZLow]), -12500);

  // alarm_reset reads back 0 after it was written.
  ASSERT_EQ(modbus_write_bit(c.get(), mm::kCoilAlarmReset, 1), 1);
  ASSERT_EQ(modbus_read_bits(c.get(), mm::kCoilAlarmReset, 1, coils), 1);
  EXPECT_EQ(coils[0], 0);
  EXPECT_EQ(cell.server.requests_served(), 13u);
}

TEST(ModbusServer, AddressesOutsideTheMapGetIllegalDataAddress) {
  Cell cell;
  auto c = connect_client(cell.server.port());
  std::uint8_t bits[8];
  std::uint16_t regs[16];
  auto expect_illegal_address = [&](int rc, const char* what) {
    EXPECT_EQ(rc, -1) << what;
    EXPECT_EQ(errno, EMBXILADD) << what << ": " << modbus_strerror(errno);
  };
  expect_illegal_address(modbus_read_bits(c.get(), mm::kCoilCount, 1, bits), "coil 7");
  expect_illegal_address(modbus_read_bits(c.get(), 98, 4, bits), "coils 98..101 (starts in the gap)");
  expect_illegal_address(modbus_read_bits(c.get(), mm::kCoilSimEnd, 1, bits), "coil 104");
  expect_illegal_address(modbus_write_bit(c.get(), 50, 1), "write coil 50");
  expect_illegal_address(modbus_read_input_bits(c.get(), 0, mm::kInputCount + 1, bits), "inputs 0..6");
  expect_illegal_address(modbus_read_input_registers(c.get(), mm::kInCount, 1, regs), "input register 20");
  expect_illegal_address(modbus_read_registers(c.get(), 3, 1, regs), "holding 3");
  expect_illegal_address(modbus_read_registers(c.get(), 0, 12, regs), "holding 0..11 (spans the gap)");
  expect_illegal_address(modbus_write_register(c.get(), 9, 1), "write holding 9");
  expect_illegal_address(modbus_read_registers(c.get(), mm::kHoldCount - 1, 2, regs), "holding 111..112");
  // The connection is still good, and nothing was written.
  ASSERT_EQ(modbus_read_registers(c.get(), mm::kHoldMailboxSeq, 2, regs), 2);
  ASSERT_EQ(modbus_read_registers(c.get(), mm::kHoldCount - 1, 1, regs), 1);
  EXPECT_TRUE(cell.locked([](Plc& p) { return p.registers().coils[50] == 0; }));
}

TEST(ModbusServer, TwoClientsAtOnce) {
  Cell cell;
  auto a = connect_client(cell.server.port());
  auto b = connect_client(cell.server.port());
  for (std::uint16_t i = 1; i <= 20; ++i) {
    ASSERT_EQ(modbus_write_register(a.get(), mm::kHoldHeartbeat, i), 1);
    std::uint16_t seen = 0;
    ASSERT_EQ(modbus_read_registers(b.get(), mm::kHoldHeartbeat, 1, &seen), 1);
    EXPECT_EQ(seen, i);
  }
  std::uint16_t count = 0;
  ASSERT_EQ(modbus_read_input_registers(a.get(), mm::kInHeartbeatSeen, 1, &count), 1);
  EXPECT_EQ(count, 20);
}

int raw_connect(int port) {
  const int s = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(static_cast<std::uint16_t>(port));
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (::connect(s, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) throw std::runtime_error("connect");
  timeval tv{3, 0};
  ::setsockopt(s, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
  return s;
}

TEST(ModbusServer, GarbageAndPartialFramesDoNotStopAGoodClient) {
  Cell cell;
  const int port = cell.server.port();
  auto good = connect_client(port);

  // A peer that sends noise, one that sends half a frame and falls silent, one that claims
  // a frame longer than any Modbus frame.
  const int noisy = raw_connect(port);
  std::vector<std::uint8_t> noise(1000);
  std::uint32_t x = 12345;
  for (auto& byte : noise) byte = static_cast<std::uint8_t>((x = x * 1103515245u + 12345u) >> 24);
  ASSERT_EQ(::send(noisy, noise.data(), noise.size(), MSG_NOSIGNAL), static_cast<ssize_t>(noise.size()));
  const int half = raw_connect(port);
  const std::uint8_t half_frame[] = {0x00, 0x01, 0x00, 0x00, 0x00, 0x06, 0x01, 0x03};
  ASSERT_EQ(::send(half, half_frame, sizeof half_frame, MSG_NOSIGNAL), static_cast<ssize_t>(sizeof half_frame));
  const int liar = raw_connect(port);
  const std::uint8_t huge[] = {0x00, 0x01, 0x00, 0x00, 0xFF, 0xFF, 0x01, 0x10, 0x00, 0x0A, 0x00, 0x7B, 0xF6};
  ASSERT_EQ(::send(liar, huge, sizeof huge, MSG_NOSIGNAL), static_cast<ssize_t>(sizeof huge));

  for (int i = 0; i < 20; ++i) {
    const auto start = Clock::now();
    std::uint16_t setpoint = 0;
    ASSERT_EQ(modbus_read_registers(good.get(), mm::kHoldPressureSetpoint, 1, &setpoint), 1)
        << "round " << i << ": " << modbus_strerror(errno);
    EXPECT_EQ(setpoint, 3800);
    // Well under the 0.5 s frame timeout: nobody waited for the half frame.
    EXPECT_LT(Clock::now() - start, std::chrono::milliseconds(300)) << "round " << i;
  }
  // The server hangs up on the silent half frame (its frame timeout) rather than waiting forever.
  std::uint8_t buf[64];
  ssize_t n;
  while ((n = ::recv(half, buf, sizeof buf, 0)) > 0) {
  }
  EXPECT_EQ(n, 0) << "the half-frame client was not closed by the server";
  for (int s : {noisy, half, liar}) ::close(s);

  std::uint16_t setpoint = 0;
  EXPECT_EQ(modbus_read_registers(good.get(), mm::kHoldPressureSetpoint, 1, &setpoint), 1);
}

TEST(ModbusServer, ClientHangingUpIsForgotten) {
  Cell cell;
  for (int i = 0; i < 50; ++i) {  // more than the client limit: hung-up clients must be released
    auto c = connect_client(cell.server.port());
    std::uint16_t v = 0;
    ASSERT_EQ(modbus_read_registers(c.get(), 0, 1, &v), 1) << "client " << i;
  }
}

TEST(ModbusServer, StopsPromptlyWithClientsConnected) {
  auto cell = std::make_unique<Cell>();
  auto c = connect_client(cell->server.port());
  const int half = raw_connect(cell->server.port());
  const std::uint8_t half_frame[] = {0x00, 0x01, 0x00};
  ::send(half, half_frame, sizeof half_frame, MSG_NOSIGNAL);
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  const auto start = Clock::now();
  cell.reset();
  EXPECT_LT(Clock::now() - start, std::chrono::milliseconds(500));
  ::close(half);
}

std::vector<std::uint16_t> block_registers(std::uint16_t seq, const std::string& text) {
  std::vector<std::uint16_t> regs{seq, static_cast<std::uint16_t>(text.size())};
  for (std::size_t i = 0; i < text.size(); i += 2) {
    const auto hi = static_cast<unsigned char>(text[i]);
    const auto lo = i + 1 < text.size() ? static_cast<unsigned char>(text[i + 1]) : 0;
    regs.push_back(static_cast<std::uint16_t>((hi << 8) | lo));
  }
  return regs;
}

TEST(ModbusServer, MailboxRoundTrip) {
  Cell cell;
  cell.locked([](Plc& p) {
    CncSnapshot s;
    s.free_blocks = 3;
    p.tick(0, s);
    return 0;
  });
  // The CNC side: takes whatever block is waiting, as the machine loop will.
  std::vector<std::string> received;
  std::atomic<bool> done{false};
  std::thread cnc([&] {
    while (!done) {
      {
        std::lock_guard lock(cell.mutex);
        if (auto block = cell.plc.pending_block()) {
          received.push_back(block->text);
          cell.plc.accept_block(block->seq);
        }
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
  });

  auto c = connect_client(cell.server.port());
  const std::vector<std::string> program{"G21 G90", "G0 X10 Y-5.25", "M3", "G1 X20 F1200 (odd length.)",
                                         std::string(200, 'Y')};
  std::uint16_t seq = 0;
  for (const auto& line : program) {
    std::uint16_t free_blocks = 0;
    ASSERT_EQ(modbus_read_input_registers(c.get(), mm::kInMailboxFree, 1, &free_blocks), 1);
    ASSERT_GT(free_blocks, 0);
    ++seq;
    const auto regs = block_registers(seq, line);  // seq first in address order: one FC16 write
    ASSERT_EQ(modbus_write_registers(c.get(), mm::kHoldMailboxSeq, static_cast<int>(regs.size()), regs.data()),
              static_cast<int>(regs.size()));
    std::uint16_t ack = 0;
    const auto deadline = Clock::now() + std::chrono::seconds(2);
    while (ack != seq && Clock::now() < deadline)
      ASSERT_EQ(modbus_read_input_registers(c.get(), mm::kInMailboxAck, 1, &ack), 1);
    ASSERT_EQ(ack, seq) << line;
  }
  done = true;
  cnc.join();
  EXPECT_EQ(received, program);
  std::uint16_t alarm = 99;
  ASSERT_EQ(modbus_read_input_registers(c.get(), mm::kInAlarmCode, 1, &alarm), 1);
  EXPECT_EQ(alarm, mm::kAlarmNone);
}

// ---- A peer nobody here wrote: Debian's mbpoll. References are 1-based unless -0 is given,
// so address a is reference a + 1 (docs/modbus-map.md).

std::string run(const std::string& command) {
  std::string out;
  FILE* p = ::popen((command + " 2>&1").c_str(), "r");
  if (!p) return out;
  char buf[512];
  while (std::fgets(buf, sizeof buf, p)) out += buf;
  const int status = ::pclose(p);
  if (status != 0) out += fmt::format("\n(exit status {})", status);
  return out;
}

// mbpoll prints one "[reference]: value" line per value read.
std::vector<std::pair<int, long>> mbpoll_values(const std::string& out) {
  std::vector<std::pair<int, long>> values;
  const std::regex line(R"(\[(\d+)\]:\s+(-?\d+))");
  for (auto it = std::sregex_iterator(out.begin(), out.end(), line); it != std::sregex_iterator(); ++it)
    values.emplace_back(std::stoi((*it)[1]), std::stol((*it)[2]));
  return values;
}

TEST(ModbusServer, ForeignPeerMbpoll) {
  if (::access("/usr/bin/mbpoll", X_OK) != 0) GTEST_SKIP() << "mbpoll is not installed (apt install mbpoll)";
  Cell cell;
  const std::string base = fmt::format("/usr/bin/mbpoll -m tcp -p {} -a 1 -1 -o 2", cell.server.port());

  // Holding 0..2, 1-based references 1..3.
  auto out = run(base + " -t 4 -r 1 -c 3 127.0.0.1");
  auto values = mbpoll_values(out);
  ASSERT_EQ(values.size(), 3u) << out;
  EXPECT_EQ(values[0], std::make_pair(1, 3800L)) << out;
  EXPECT_EQ(values[2], std::make_pair(3, 350L)) << out;

  // Write the heartbeat (holding 1 = reference 2) and the pump coil (coil 0 = reference 1).
  out = run(base + " -t 4 -r 2 127.0.0.1 4242");
  EXPECT_EQ(out.find("exit status"), std::string::npos) << out;
  out = run(base + " -t 0 -r 1 127.0.0.1 1");
  EXPECT_EQ(out.find("exit status"), std::string::npos) << out;
  EXPECT_TRUE(cell.locked([](Plc& p) {
    return p.registers().holding[mm::kHoldHeartbeat] == 4242 && p.registers().coils[mm::kCoilPumpEnable] == 1;
  }));

  // Read them back, and a signed 32-bit position (high word first: mbpoll's -B).
  out = run(base + " -t 0 -r 1 -c 4 127.0.0.1");
  values = mbpoll_values(out);
  ASSERT_EQ(values.size(), 4u) << out;
  EXPECT_EQ(values[0].second, 1) << out;
  EXPECT_EQ(values[3].second, 0) << out;
  out = run(base + " -t 3 -r 4 127.0.0.1");  // heartbeat_seen = input register 3
  values = mbpoll_values(out);
  ASSERT_EQ(values.size(), 1u) << out;
  EXPECT_EQ(values[0], std::make_pair(4, 1L)) << out;
  cell.locked([](Plc& p) {
    CncSnapshot s;
    s.position[0] = -1234.567;
    p.tick(0.1, s);
    return 0;
  });
  out = run(base + fmt::format(" -t 3:int -B -r {} 127.0.0.1", mm::kInPositionXHigh + 1));
  values = mbpoll_values(out);
  ASSERT_EQ(values.size(), 1u) << out;
  EXPECT_EQ(values[0].second, -1234567) << out;

  // An address outside the map: mbpoll reports the exception and fails.
  out = run(base + " -t 4 -r 5 127.0.0.1");  // holding 4
  EXPECT_NE(out.find("exit status"), std::string::npos) << out;
  EXPECT_TRUE(mbpoll_values(out).empty()) << out;
}

}  // namespace
}  // namespace lamina::sim
