// ModbusBlockLink against the lamina-sim PLC mailbox: a program streamed line for line, feed
// hold and resume through the PLC's CNC coils, a line too long for the mailbox, and the PLC
// going away mid-stream.
#include <gtest/gtest.h>

#include <fmt/format.h>

#include <future>

#include "lamina/drivers/modbus_block_link.hpp"
#include "modbus_test_client.hpp"

namespace lamina::drivers {
namespace {
using namespace testing;

ModbusBlockSettings settings_for(int port) {
  ModbusBlockSettings s;
  s.plc.port = port;
  s.ack_timeout_s = 2;
  s.status_period_s = 0.05;
  return s;
}

// Short moves, a comment and odd and even lengths: every shape of block the mailbox carries.
std::vector<std::string> program_of(std::size_t n, double feed_mm_per_min) {
  std::vector<std::string> lines{"G21G90G94", "(contour 1)"};
  for (std::size_t i = 0; lines.size() < n; ++i)
    lines.push_back(fmt::format("G1X{:.1f}Y{}F{}", 10 + (i % 50) * 0.5, 5 + i % 7, feed_mm_per_min));
  return lines;
}

TEST(ModbusBlockLink, StreamsAProgramThatTheCncExecutesLineForLine) {
  SimCell cell({"--time-scale", "50"});
  ModbusBlockLink link(settings_for(cell.sim.modbus_port()));
  const auto program = program_of(200, 3000);
  link.start(LineSpan{program, 0}, {});
  const auto outcome = link.wait(30);
  ASSERT_TRUE(outcome);
  ASSERT_TRUE(outcome->completed) << (outcome->error ? outcome->error->message : "");
  EXPECT_EQ(outcome->last_accepted_index, 199u);
  EXPECT_EQ(link.progress().lines_accepted, 200u);
  ASSERT_TRUE(wait_status(cell.sim.control_port(),
                          [&](const nlohmann::json& st) { return st["executed_blocks"] == program.size(); }, 20));
  const auto blocks = executed_blocks(read_log(cell.log()));
  ASSERT_EQ(blocks.size(), program.size());
  for (std::size_t i = 0; i < blocks.size(); ++i) EXPECT_EQ(blocks[i]["line"], program[i]) << "block " << i;
}

TEST(ModbusBlockLink, ASecondJobContinuesTheSequenceNumbers) {
  SimCell cell({"--time-scale", "50"});
  const auto program = program_of(10, 3000);
  for (int job = 0; job < 2; ++job) {  // a fresh link object each time, as after a daemon restart
    ModbusBlockLink link(settings_for(cell.sim.modbus_port()));
    link.start(LineSpan{program, 0}, {});
    const auto outcome = link.wait(10);
    ASSERT_TRUE(outcome && outcome->completed) << "job " << job;
  }
  ASSERT_TRUE(wait_status(cell.sim.control_port(), [](const nlohmann::json& st) { return st["executed_blocks"] == 20; }, 10));
}

// The job completes, and the CNC executes every block of it.
void expect_completes(ModbusBlockLink& link, const SimCell& cell, const std::vector<std::string>& program) {
  link.start(LineSpan{program, 0}, {});
  const auto outcome = link.wait(30);
  ASSERT_TRUE(outcome);
  ASSERT_TRUE(outcome->completed) << (outcome->error ? outcome->error->message : "");
  ASSERT_TRUE(wait_status(cell.sim.control_port(),
                          [&](const nlohmann::json& st) { return st["executed_blocks"] == program.size(); }, 20));
}

// The CNC takes a jet M-code only once its queue has drained (planner sync): a mailbox block
// may wait for seconds of cutting. That is a busy CNC, not a lost block: no timeout.
TEST(ModbusBlockLink, AJetChangeWaitingForTheQueueToDrainIsNoTimeout) {
  SimCell cell({"--time-scale", "1"});
  auto settings = settings_for(cell.sim.modbus_port());
  settings.ack_timeout_s = 0.5;
  ModbusBlockLink link(settings);
  auto program = program_of(20, 600);  // 18 moves of 1-6 mm at 10 mm/s: ~3 s queued ahead of M5
  program.insert(program.end(), {"M5", "G0X0Y0"});
  expect_completes(link, cell, program);
}

// A dwelling CNC stands Idle on its state lamps (grblHAL plans nothing for G4) and takes the
// block behind the dwell only when it ends: the dwell's P is no lost block either.
TEST(ModbusBlockLink, TheBlockBehindADwellLongerThanTheAckTimeoutIsNoTimeout) {
  SimCell cell({"--time-scale", "1"});
  auto settings = settings_for(cell.sim.modbus_port());
  settings.ack_timeout_s = 0.5;
  ModbusBlockLink link(settings);
  const std::vector<std::string> program{"G21G90G94", "G1X5F600", "M3", "G4P1.5", "G1X6", "M5"};
  expect_completes(link, cell, program);
}

TEST(ModbusBlockLink, FeedHoldAndResumeGoThroughThePlcCoils) {
  SimCell cell({"--planner-blocks", "5"});  // the queue fills: the job is still streaming when stopped
  ModbusBlockLink link(settings_for(cell.sim.modbus_port()));
  std::vector<std::string> program{"G21G90G94"};
  for (int i = 1; i <= 20; ++i) program.push_back(fmt::format("G1X{}F600", i % 2 ? 100 : 0));  // 10 s each
  link.start(LineSpan{program, 0}, {});
  auto state = [&] {
    link.request(RealtimeCommand::status);
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    const auto st = link.progress().last_status;
    return st ? st->state : ControllerState::unknown;
  };
  ASSERT_TRUE(eventually([&] { return state() == ControllerState::run; }, 5));
  link.request(RealtimeCommand::feed_hold);
  ASSERT_TRUE(eventually([&] { return state() == ControllerState::hold; }, 5)) << "hold via coil 4";
  EXPECT_EQ(link.progress().last_status->state_text, "Hold:0");
  link.request(RealtimeCommand::resume);
  ASSERT_TRUE(eventually([&] { return state() == ControllerState::run; }, 5)) << "resume via coil 5";
  link.stop(LinkError{LinkErrorCode::cancelled, "test over"});
  const auto outcome = link.wait(5);
  ASSERT_TRUE(outcome);
  EXPECT_FALSE(outcome->completed);
  ASSERT_TRUE(outcome->error);
  EXPECT_EQ(outcome->error->code, LinkErrorCode::cancelled);
  int presses = 0;
  for (const auto& r : read_log(cell.log()))
    if (r.value("event", "") == "plc_button") ++presses;
  EXPECT_EQ(presses, 2);
}

TEST(ModbusBlockLink, ALineTooLongForTheMailboxIsRefusedBeforeAnythingIsSent) {
  SimCell cell;
  ModbusBlockLink link(settings_for(cell.sim.modbus_port()));
  std::vector<std::string> program{"G21G90", "G1X1F600", "(" + std::string(205, 'x') + ")"};
  std::promise<LinkOutcome> done;
  LinkCallbacks callbacks;
  callbacks.on_done = [&](const LinkOutcome& o) { done.set_value(o); };
  link.start(LineSpan{program, 40}, callbacks);
  auto future = done.get_future();
  ASSERT_EQ(future.wait_for(std::chrono::seconds(5)), std::future_status::ready);
  const LinkOutcome outcome = future.get();
  ASSERT_TRUE(outcome.error);
  EXPECT_EQ(outcome.error->code, LinkErrorCode::bad_request);
  EXPECT_NE(outcome.error->message.find("line 43 '("), std::string::npos) << outcome.error->message;  // index 42
  EXPECT_EQ(control_status(cell.sim.control_port())["accepted_blocks"], 0);
  PlcProbe plc(cell.sim.modbus_port());
  EXPECT_EQ(plc.hold(10), 0) << "no mailbox write at all";
}

TEST(ModbusBlockLink, ThePlcGoingAwayMidStreamEndsTheJobWithAnError) {
  auto cell = std::make_unique<SimCell>();
  ModbusBlockLink link(settings_for(cell->sim.modbus_port()));
  const auto program = program_of(200, 60);  // slow moves: the queue fills and streaming waits for room
  link.start(LineSpan{program, 0}, {});
  ASSERT_TRUE(eventually([&] { return link.progress().lines_accepted >= 20; }, 10));
  const auto t0 = std::chrono::steady_clock::now();
  cell->sim.stop();
  const auto outcome = link.wait(5);
  ASSERT_TRUE(outcome) << "no on_done within 5 s";
  EXPECT_LT(seconds_since(t0), 3.0);
  EXPECT_FALSE(outcome->completed);
  ASSERT_TRUE(outcome->error);
  EXPECT_EQ(outcome->error->code, LinkErrorCode::modbus_error);
  EXPECT_NE(outcome->error->message.find("line "), std::string::npos) << outcome->error->message;
  EXPECT_NE(outcome->error->message.find("reconnects"), std::string::npos) << outcome->error->message;
}

}  // namespace
}  // namespace lamina::drivers
