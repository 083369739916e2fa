// The block mailbox link's sequences against an in-memory PLC (issue 18: the Modbus seam): how
// it numbers, writes and waits for each block, what stops it — with no TCP server and no
// simulator. docs/modbus-map.md, "Block mailbox", is the contract; test_modbus_block_link.cpp
// checks the same link against the simulator's PLC in another process.
#include <gtest/gtest.h>

#include <chrono>
#include <thread>

#include "lamina/drivers/modbus_block_link.hpp"
#include "memory_plc.hpp"

namespace lamina::drivers::testing {
namespace {

struct MailboxLink {
  MemoryPlc* plc = nullptr;  // owned by link
  std::unique_ptr<ModbusBlockLink> link;
  std::vector<std::string> lines;
  explicit MailboxLink(double ack_timeout_s = 30) {
    auto bus = std::make_unique<MemoryPlc>();
    plc = bus.get();
    ModbusBlockSettings s;
    s.ack_timeout_s = ack_timeout_s;
    link = std::make_unique<ModbusBlockLink>(s, std::move(bus));
  }
  void start(std::vector<std::string> program) {
    lines = std::move(program);
    link->start(LineSpan{lines, 0}, {});
  }
  // The outcome, bounded: a link that never finishes fails the test instead of hanging it.
  LinkOutcome outcome() {
    auto o = link->wait(60);
    EXPECT_TRUE(o.has_value()) << "the link did not finish within 60 s";
    return o.value_or(LinkOutcome{});
  }
};

// Bounded wait for a condition the link's own thread brings about.
template <class Done>
bool eventually(Done done) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  while (!done()) {
    if (std::chrono::steady_clock::now() > deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  return true;
}

TEST(MailboxSequence, EachBlockGoesInOneWriteWithTheNextSequenceNumberAfterThePlcsLast) {
  MailboxLink m;
  m.plc->set_holding_register(MemoryPlc::kHoldMailboxSeq, 65534);  // left by an earlier job
  m.start({"G21", "G0X1.5", "M30"});
  const LinkOutcome o = m.outcome();
  ASSERT_TRUE(o.completed) << (o.error ? o.error->message : "");
  // 65535 then 1: zero is the power-on value and never used.
  EXPECT_EQ(m.plc->blocks(), (std::vector<std::string>{"65535: G21", "1: G0X1.5", "2: M30"}));
  std::vector<std::string> mailbox_writes;
  for (const auto& w : m.plc->writes())
    if (w.starts_with("hold 10")) mailbox_writes.push_back(w);
  EXPECT_EQ(mailbox_writes, (std::vector<std::string>{"hold 10..13 (4 registers)", "hold 10..14 (5 registers)",
                                                      "hold 10..13 (4 registers)"}))
      << "seq, length and text in one FC16 request per block";
}

TEST(MailboxSequence, TheNextBlockWaitsForTheAcknowledgeOfThePrevious) {
  MailboxLink m;
  m.plc->hold_acks(true);  // the CNC's queue is busy: blocks stay pending
  m.start({"G0X1", "G0X2"});
  ASSERT_TRUE(eventually([&] { return m.plc->blocks().size() == 1; }));
  // However often the link polls while waiting, no second block is written (an overrun).
  const long reads = m.plc->input_reads();
  ASSERT_TRUE(eventually([&] { return m.plc->input_reads() >= reads + 5; }));
  EXPECT_EQ(m.plc->blocks().size(), 1u);
  m.plc->hold_acks(false);
  m.plc->accept_pending();
  const LinkOutcome o = m.outcome();
  ASSERT_TRUE(o.completed) << (o.error ? o.error->message : "");
  EXPECT_EQ(m.plc->blocks(), (std::vector<std::string>{"1: G0X1", "2: G0X2"}));
}

TEST(MailboxSequence, NoBlockIsWrittenWhileTheQueueHasNoRoom) {
  MailboxLink m;
  m.plc->set_input_register(MemoryPlc::kInMailboxFree, 0);
  m.start({"G0X1"});
  const long reads = m.plc->input_reads();
  ASSERT_TRUE(eventually([&] { return m.plc->input_reads() >= reads + 5; }));
  EXPECT_TRUE(m.plc->blocks().empty()) << "a block was written while mailbox_free was 0";
  m.plc->set_input_register(MemoryPlc::kInMailboxFree, 1);
  const LinkOutcome o = m.outcome();
  ASSERT_TRUE(o.completed) << (o.error ? o.error->message : "");
  EXPECT_EQ(m.plc->blocks(), std::vector<std::string>{"1: G0X1"});
}

TEST(MailboxSequence, ARefusedBlockStopsTheJobNamingTheLine) {
  MailboxLink m;
  // The second block is refused. (Refused "next" after the start, the refusal raced the link's
  // thread: on a loaded machine all three blocks were through first and the job completed.)
  m.plc->refuse_block(2);
  m.start({"G21", "G0X1", "G0X2"});
  const LinkOutcome o = m.outcome();
  ASSERT_FALSE(o.completed);
  ASSERT_TRUE(o.error.has_value());
  EXPECT_EQ(o.error->code, LinkErrorCode::controller_error) << o.error->message;
  EXPECT_NE(o.error->message.find("mailbox bad block"), std::string::npos) << o.error->message;
  EXPECT_NE(o.error->message.find("line 2 'G0X1'"), std::string::npos) << o.error->message;
  EXPECT_EQ(m.plc->blocks(), std::vector<std::string>{"1: G21"}) << "nothing is sent after the refusal";
}

TEST(MailboxSequence, AMailboxAlarmLeftFromAnEarlierJobIsResetBeforeTheFirstBlock) {
  MailboxLink m;
  m.plc->latch_alarm(MemoryPlc::kAlarmMailboxOverrun);
  m.start({"G0X1"});
  const LinkOutcome o = m.outcome();
  ASSERT_TRUE(o.completed) << (o.error ? o.error->message : "");
  const long reset = m.plc->first("coil 3 = 1");
  const long block = m.plc->first("hold 10..13 (4 registers)");
  ASSERT_GE(reset, 0) << "alarm_reset was not pressed";
  ASSERT_GE(block, 0);
  EXPECT_LT(reset, block);
}

TEST(MailboxSequence, ABlockLeftUntakenByAnIdleCncTimesOut) {
  MailboxLink m(0.3);
  m.plc->hold_acks(true);  // cnc_state stays 0 (idle): nothing excuses the missing acknowledge
  m.start({"G0X1", "G0X2"});
  const LinkOutcome o = m.outcome();
  ASSERT_FALSE(o.completed);
  ASSERT_TRUE(o.error.has_value());
  EXPECT_EQ(o.error->code, LinkErrorCode::timeout) << o.error->message;
  EXPECT_NE(o.error->message.find("not acknowledged"), std::string::npos) << o.error->message;
  EXPECT_EQ(m.plc->blocks().size(), 1u);
}

TEST(MailboxSequence, FeedHoldIsTheCncsHoldButton) {
  MailboxLink m;
  m.link->request(RealtimeCommand::feed_hold);
  ASSERT_TRUE(eventually([&] { return m.plc->first("coil 4 = 1") >= 0; }));
}

}  // namespace
}  // namespace lamina::drivers::testing
