// lamina-sim's other ways in: the Fanuc-style XON/XOFF drip feed on the PTY, and the Modbus
// block mailbox — each executes the program line for line.
#include <gtest/gtest.h>

#include <algorithm>

#include <modbus/modbus.h>

#include "grbl_client.hpp"
#include "sim_process.hpp"

namespace lamina::sim::testing {
namespace {

constexpr char kDc1 = 0x11, kDc3 = 0x13, kNak = 0x15;

struct XonSim : LoggedSim {
  explicit XonSim(std::vector<std::string> extra) : LoggedSim(std::move(extra), {"--personality", "xonxoff"}) {}
};

// Send bytes one at a time while the controller has not said DC3; wait for DC1 after one.
struct DripResult {
  int dc3 = 0, dc1 = 0;
  bool nak = false;
};
DripResult drip_feed(StreamClient& c, const std::string& text, double timeout_s) {
  DripResult r;
  bool stopped = false;
  std::size_t seen = 0, sent = 0;
  const auto t0 = std::chrono::steady_clock::now();
  while (sent < text.size() && seconds_since(t0) < timeout_s) {
    c.read_until([](const std::string&) { return false; }, stopped ? 0.01 : 0.0);
    for (; seen < c.buffer().size(); ++seen) {
      const char b = c.buffer()[seen];
      if (b == kDc3) ++r.dc3, stopped = true;
      if (b == kDc1) ++r.dc1, stopped = false;
      if (b == kNak) r.nak = true;
    }
    if (r.nak) break;
    if (!stopped) {
      const std::size_t n = std::min<std::size_t>(16, text.size() - sent);  // small writes: stop promptly
      c.send(text.substr(sent, n));
      sent += n;
      // Pace the writes to the wire (115200 baud): what a sender has handed the kernel can no
      // longer be held back by a DC3, so a drip feeder keeps that backlog small.
      std::this_thread::sleep_for(std::chrono::microseconds(n * 1'000'000 / 11'520));
    }
  }
  return r;
}

TEST(SimXonXoff, DripFeedPausesOnDc3ResumesOnDc1AndRunsTheProgram) {
  XonSim s({"--rx-buffer", "256", "--planner-blocks", "8"});  // real time: the machine is slower than the wire
  StreamClient c = StreamClient::open_pty(s.link);
  const auto program = five_axis_program(150);
  std::string text = "%\n";
  for (const auto& line : program) text += line + "\n";
  text += "%\n";
  const DripResult r = drip_feed(c, text, 60);
  EXPECT_FALSE(r.nak) << "no alarm";
  EXPECT_GT(r.dc3, 0) << "a 5 kB program through a 256-byte buffer must be paused";
  EXPECT_GT(r.dc1, 0);
  ASSERT_TRUE(wait_status(s.sim.control_port(), [&](const nlohmann::json& st) {
    return st["executed_blocks"] == program.size();
  }, 30));
  const auto blocks = executed_blocks(read_log(s.log));
  ASSERT_EQ(blocks.size(), program.size());
  for (std::size_t i = 0; i < blocks.size(); ++i) EXPECT_EQ(blocks[i]["line"], program[i]);
  EXPECT_EQ(control_status(s.sim.control_port())["bytes_dropped"], 0);
}

TEST(SimXonXoff, IgnoringDc3OverrunsAndAlarmsWithNak) {
  XonSim s({"--rx-buffer", "256", "--planner-blocks", "2"});
  StreamClient c = StreamClient::open_pty(s.link);
  std::string text = "%\n";
  for (int i = 0; i < 200; ++i) text += "G4P1\n";
  c.send(text);  // all at once, deaf to DC3
  ASSERT_TRUE(c.read_until([](const std::string& b) { return b.find(kNak) != std::string::npos; }, 5));
  const auto dc3 = c.buffer().find(kDc3);
  ASSERT_NE(dc3, std::string::npos);
  EXPECT_LT(dc3, c.buffer().find(kNak)) << "DC3 then NAK";
  const auto st = control_status(s.sim.control_port());
  EXPECT_GT(st["bytes_dropped"].get<int>(), 0);
  EXPECT_EQ(st["state"], "alarm");
}

TEST(SimXonXoff, ResetSendsDc3ThenSyn) {
  XonSim s({});
  StreamClient c = StreamClient::open_pty(s.link);
  c.read_until([](const std::string&) { return false; }, 0.2);
  c.buffer().clear();
  EXPECT_EQ(control(s.sim.control_port(), "reset"), "ok");
  ASSERT_TRUE(c.read_until([](const std::string& b) { return b.find('\x16') != std::string::npos; }, 2));
  EXPECT_EQ(c.buffer().find(kDc3), c.buffer().find('\x16') - 1) << "DC3 immediately before SYN";
}

// One FC16 write into the PLC's mailbox: sequence number, length, text two characters a register.
bool write_mailbox(modbus_t* ctx, uint16_t seq, const std::string& block) {
  uint16_t regs[2 + 100] = {};
  regs[0] = seq;
  regs[1] = static_cast<uint16_t>(block.size());
  for (std::size_t i = 0; i < block.size(); ++i)
    regs[2 + i / 2] |= static_cast<uint16_t>(static_cast<uint8_t>(block[i]) << (i % 2 == 0 ? 8 : 0));
  const int count = static_cast<int>(2 + (block.size() + 1) / 2);
  return modbus_write_registers(ctx, 10, count, regs) == count;
}

// mailbox_ack once it equals `seq`, or whatever it is after `wait_s`.
uint16_t wait_ack(modbus_t* ctx, uint16_t seq, double wait_s) {
  uint16_t ack = 0;
  const auto t0 = std::chrono::steady_clock::now();
  do modbus_read_input_registers(ctx, 4, 1, &ack);
  while (ack != seq && seconds_since(t0) < wait_s);
  return ack;
}

TEST(SimMailbox, BlocksWrittenOverModbusExecuteInOrder) {
  TempDir dir;
  SimProcess sim({"--link", dir.file("cnc"), "--modbus", "127.0.0.1:0", "--log", dir.file("exec.jsonl"),
                  "--control", "127.0.0.1:0", "--time-scale", "20"});
  modbus_t* ctx = modbus_new_tcp("127.0.0.1", sim.modbus_port());
  ASSERT_EQ(modbus_connect(ctx), 0);
  const std::vector<std::string> program{"G21G90G94", "G0X10Y10", "G1X20Y15F1200", "G93G1X30A10C45F600", "G94"};
  uint16_t seq = 0;
  for (const auto& block : program) {
    ++seq;
    // Wait for room, then one FC16 write: seq, length, text.
    uint16_t free_blocks = 0;
    for (int i = 0; i < 200 && free_blocks == 0; ++i) modbus_read_input_registers(ctx, 5, 1, &free_blocks);
    ASSERT_GT(free_blocks, 0);
    ASSERT_TRUE(write_mailbox(ctx, seq, block));
    ASSERT_EQ(wait_ack(ctx, seq, 2), seq) << "block " << block;
  }
  modbus_close(ctx);
  modbus_free(ctx);
  ASSERT_TRUE(wait_status(sim.control_port(), [&](const nlohmann::json& st) {
    return st["executed_blocks"] == program.size();
  }, 10));
  const auto blocks = executed_blocks(read_log(dir.file("exec.jsonl")));
  ASSERT_EQ(blocks.size(), program.size());
  for (std::size_t i = 0; i < blocks.size(); ++i) EXPECT_EQ(blocks[i]["line"], program[i]);
  EXPECT_NEAR(blocks.back()["end"][4].get<double>(), 45, 1e-9);
}

// A jet-on block waits in the mailbox for the motion before it (the planner sync). A reset in
// the meantime stops the program: the block must die with it, not turn the jet on afterwards.
TEST(SimMailbox, AJetOnBlockWaitingForTheDrainDiesWithAReset) {
  TempDir dir;
  SimProcess sim({"--link", dir.file("cnc"), "--modbus", "127.0.0.1:0", "--log", dir.file("exec.jsonl"),
                  "--control", "127.0.0.1:0"});
  modbus_t* ctx = modbus_new_tcp("127.0.0.1", sim.modbus_port());
  ASSERT_EQ(modbus_connect(ctx), 0);
  ASSERT_TRUE(write_mailbox(ctx, 1, "G1X50F600"));  // 5 s of motion
  ASSERT_EQ(wait_ack(ctx, 1, 2), 1);
  ASSERT_TRUE(write_mailbox(ctx, 2, "M3"));
  EXPECT_EQ(wait_ack(ctx, 2, 0.3), 1) << "M3 waits for the move to finish";
  EXPECT_EQ(control(sim.control_port(), "reset"), "ok");
  EXPECT_EQ(wait_ack(ctx, 2, 0.5), 1) << "never taken";
  const auto st = control_status(sim.control_port());
  EXPECT_EQ(st["queued_blocks"], 0);
  EXPECT_EQ(st["accepted_blocks"], 1) << "the M3 never reached the CNC";
  modbus_close(ctx);
  modbus_free(ctx);
  const auto log = read_log(dir.file("exec.jsonl"));
  EXPECT_TRUE(std::any_of(log.begin(), log.end(), [](const nlohmann::json& r) {
    return r.value("event", "") == "mailbox_discarded" && r.value("why", "") == "reset";
  }));
  for (const auto& b : executed_blocks(log)) EXPECT_FALSE(b["jet"].get<bool>()) << b.dump();
}

}  // namespace
}  // namespace lamina::sim::testing
