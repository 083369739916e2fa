// Before anything is sent, a program line that holds a real-time byte of the chosen protocol is
// refused with its line and column (issue 16, item 2): a controller takes such a byte the
// moment it arrives, inside a comment too — `(mind the clamps!)` after M3 held a grbl machine
// with the jet on, forever; a ctrl-X reset it.
#include <gtest/gtest.h>

#include <functional>

#include "lamina/drivers/line_protocol.hpp"
#include "link_test_support.hpp"
#include "modbus_test_client.hpp"

namespace lamina::drivers::testing {
namespace {

std::optional<LinkError> check(const LineProtocol& p, std::vector<std::string> lines, std::size_t first = 0) {
  return p.check_lines(lines, first);
}

TEST(ProgramCheck, GrblRefusesItsRealtimeBytesAnywhereInALine) {
  const std::vector<std::function<std::unique_ptr<LineProtocol>()>> protocols{
      [] { return make_grbl_protocol(); }, [] { return make_send_response_protocol(); }};
  for (const auto& make : protocols) {
    const auto p = make();
    EXPECT_FALSE(check(*p, {"G21G90G94", "(CONTOUR 0 L1-1 OUTLINE 0)", "M3", "G1X1Y2F600 ; fine", "%"}))
        << p->name() << ": a clean program";
    const auto bang = check(*p, {"G21", "M3", "(mind the clamps!)", "G1X1"});
    ASSERT_TRUE(bang) << p->name();
    EXPECT_EQ(bang->code, LinkErrorCode::bad_request);
    EXPECT_NE(bang->message.find("line 3, column 17: '!' is a feed hold"), std::string::npos) << bang->message;
    EXPECT_NE(bang->message.find("nothing was sent"), std::string::npos);
    EXPECT_NE(check(*p, {"G1X1(why?)"})->message.find("'?' is the status request"), std::string::npos);
    EXPECT_NE(check(*p, {"(~)"})->message.find("cycle start"), std::string::npos);
    EXPECT_NE(check(*p, {"G1X1\x18"})->message.find("0x18 is a soft reset"), std::string::npos);
    // UTF-8 in a comment: 0xC2 0xB0 (°) are top-bit bytes, grblHAL's extended commands.
    EXPECT_NE(check(*p, {"(tilt 30\xC2\xB0)"})->message.find("line 1, column 9: 0xC2"), std::string::npos);
    EXPECT_NE(check(*p, {"G0Z5", "(!)"}, 100)->message.find("line 102,"), std::string::npos)
        << "a resumed span keeps the program's numbering";
  }
}

TEST(ProgramCheck, XonXoffRefusesTapeControlCodesAndAPercentInsideTheProgram) {
  const auto p = make_xonxoff_protocol();
  EXPECT_FALSE(check(*p, {"%", "O1000", "G1X1(mind the clamps!)", "M30", "%"})) << "'!' means nothing to a Fanuc";
  EXPECT_FALSE(check(*p, {"G0Z5", "M30", "%"}, 40)) << "a resumed span ends with the program's own %";
  for (const char c : {'\x11', '\x12', '\x13', '\x14'}) {
    const auto bad = check(*p, {"O1000", std::string("G1X1") + c});
    ASSERT_TRUE(bad) << static_cast<int>(c);
    EXPECT_NE(bad->message.find("line 2, column 5"), std::string::npos) << bad->message;
  }
  const auto percent = check(*p, {"%", "O1000", "G1X1(50%)", "%"});
  ASSERT_TRUE(percent);
  EXPECT_NE(percent->message.find("'%' is the end of the program"), std::string::npos) << percent->message;
}

// Through the CLI, as an operator streams a program from elsewhere: refused before the pump
// starts or the port opens.
TEST(ProgramCheck, AStreamOfAProgramWithARealtimeByteIsRefusedBeforeAnythingHappens) {
  SimCell cell;
  const auto program = contour_program(1, 10);
  auto bad = program;
  bad.insert(bad.begin() + 6, "(mind the clamps!)");
  const CliRun run = run_lamina_stream(fmt::format("'{}' --port '{}' --modbus 127.0.0.1:{}", write_program(cell.dir, bad),
                                                   cell.dir.file("cnc"), cell.sim.modbus_port()));
  EXPECT_EQ(run.exit_code, 1) << run.output;
  EXPECT_EQ(run.summary["state"], "failed") << run.output;
  EXPECT_EQ(run.summary["reason"]["code"], "bad_request") << run.output;
  EXPECT_NE(run.summary["reason"]["message"].get<std::string>().find("line 7, column 17"), std::string::npos)
      << run.output;
  const auto status = control_status(cell.sim.control_port());
  EXPECT_EQ(status["bytes_received"], 0) << "the CNC heard nothing: " << status.dump();
  PlcProbe plc(cell.sim.modbus_port());
  EXPECT_EQ(plc.coil(map::kCoilPump), 0) << "the pump never started";
  EXPECT_EQ(plc.coil(map::kCoilAbrasive), 0);
}

}  // namespace
}  // namespace lamina::drivers::testing
