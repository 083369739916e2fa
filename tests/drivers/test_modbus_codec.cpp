// The pure parts of the Modbus drivers: the mailbox encoding (docs/modbus-map.md "Block
// mailbox"), sequence numbers, CNC status decoding and the interlock rules.
#include <gtest/gtest.h>

#include "cell_interlocks.hpp"
#include "mailbox_codec.hpp"

namespace lamina::drivers {
namespace {

TEST(MailboxCodec, TwoCharactersPerRegisterHighByteFirstOddLastInTheHighByte) {
  const auto regs = encode_mailbox_block(7, "G1X");
  ASSERT_EQ(regs.size(), 4u);
  EXPECT_EQ(regs[0], 7);  // seq
  EXPECT_EQ(regs[1], 3);  // length
  EXPECT_EQ(regs[2], ('G' << 8) | '1');
  EXPECT_EQ(regs[3], 'X' << 8);
  EXPECT_EQ(encode_mailbox_block(1, "").size(), 2u);
  EXPECT_EQ(encode_mailbox_block(1, std::string(200, 'a')).size(), 102u);
}

TEST(MailboxCodec, SequenceNumbersSkipZero) {
  EXPECT_EQ(next_mailbox_seq(0), 1);
  EXPECT_EQ(next_mailbox_seq(1), 2);
  EXPECT_EQ(next_mailbox_seq(65535), 1);
}

TEST(MailboxCodec, BlocksTheMailboxCannotCarryAreBadRequests) {
  EXPECT_FALSE(check_mailbox_block(0, std::string(200, 'a')));
  EXPECT_FALSE(check_mailbox_block(0, "G1\tX1"));
  const auto long_line = check_mailbox_block(9, std::string(201, 'a'));
  ASSERT_TRUE(long_line);
  EXPECT_EQ(long_line->code, LinkErrorCode::bad_request);
  EXPECT_NE(long_line->message.find("line 10 '"), std::string::npos) << long_line->message;  // index 9, counted from 1
  EXPECT_TRUE(check_mailbox_block(0, "G1X1\rG1X2"));
}

TEST(MailboxCodec, CncStatusInMillimetresAndDegrees) {
  std::vector<std::uint16_t> r(20, 0);
  r[5] = 12;             // mailbox_free
  r[7] = 3;              // hold
  r[8] = 1, r[9] = 2;    // executed = 65538
  r[10] = 0, r[11] = 1500;  // X = 1500 µm
  const auto minus_250 = static_cast<std::uint32_t>(-250);
  r[14] = static_cast<std::uint16_t>(minus_250 >> 16), r[15] = static_cast<std::uint16_t>(minus_250 & 0xFFFF);
  r[16] = 0x0001, r[17] = 0x5F90;  // A = 90000 millidegrees
  const ControllerStatus s = decode_cnc_status(r);
  EXPECT_EQ(s.state, ControllerState::hold);
  EXPECT_EQ(s.state_text, "Hold:0");
  EXPECT_EQ(*s.executed_blocks, 65538u);
  EXPECT_EQ(*s.planner_blocks_free, 12);
  EXPECT_DOUBLE_EQ((*s.machine_position)[0], 1.5);
  EXPECT_DOUBLE_EQ((*s.machine_position)[2], -0.25);
  EXPECT_DOUBLE_EQ((*s.machine_position)[3], 90.0);
}

TEST(CellInterlocks, OrderAndMessages) {
  CellIoSettings settings;  // 380 MPa, fraction 0.9
  CellStatus s;
  s.estop_ok = s.door_closed = s.pump_ready = true;
  s.pressure_mpa = 380;
  EXPECT_FALSE(check_interlocks(s, settings));
  s.pressure_mpa = 112;
  auto f = check_interlocks(s, settings);
  ASSERT_TRUE(f);
  EXPECT_EQ(f->fault, CellFault::pressure_low);
  EXPECT_EQ(f->message, "pressure 112.0 MPa < 342.0 MPa (0.9 × 380.0 MPa)");
  s.door_closed = false;
  EXPECT_EQ(check_interlocks(s, settings)->fault, CellFault::door_open);
  s.estop_ok = false;
  EXPECT_EQ(check_interlocks(s, settings)->fault, CellFault::estop);
}

}  // namespace
}  // namespace lamina::drivers
