// CellIo's sequences against an in-memory PLC (issue 18: the Modbus seam): what it switches, in
// which order, with no TCP server and no simulator. The simulator tests (test_cell_io.cpp) check
// the same against a PLC in another process; these pin the order down.
#include <gtest/gtest.h>

#include "lamina/drivers/cell_io.hpp"
#include "memory_plc.hpp"

namespace lamina::drivers::testing {
namespace {

struct Cell {
  MemoryPlc* plc = nullptr;  // owned by io
  std::unique_ptr<CellIo> io;
  Cell() {
    auto bus = std::make_unique<MemoryPlc>();
    plc = bus.get();
    CellIoSettings s;
    s.pressure_setpoint_01mpa = 3800;
    s.abrasive_g_per_min = 350;
    s.idle_poll_period_s = 0;  // nothing but the sequences in the log
    io = std::make_unique<CellIo>(s, std::move(bus));
  }
};

TEST(CellIoSequence, PrepareRaisesThePressureThenAbrasiveThenBeatsThenConsentsTheJet) {
  Cell cell;
  auto r = cell.io->prepare_cut();
  ASSERT_TRUE(r) << r.error().message;
  const MemoryPlc& plc = *cell.plc;
  const long setpoint = plc.first("hold 0 = 3800"), pump = plc.first("coil 0 = 1"),
             abrasive_setpoint = plc.first("hold 2 = 350"), abrasive = plc.first("coil 1 = 1"),
             beat = plc.first("heartbeat"), jet = plc.first("coil 2 = 1");
  for (long at : {setpoint, pump, abrasive_setpoint, abrasive, beat, jet}) ASSERT_GE(at, 0) << fmt::format("{}", plc.writes());
  EXPECT_LT(setpoint, pump) << "the set point before the pump starts";
  EXPECT_LT(pump, abrasive) << "abrasive only into a running jet of water";
  EXPECT_LT(abrasive_setpoint, abrasive);
  EXPECT_LT(beat, jet) << "the watchdog is fed before the jet is consented";
  EXPECT_LT(abrasive, jet);
  EXPECT_EQ(plc.writes().back() == "coil 2 = 1" || plc.writes().back() == "heartbeat", true) << "the jet consent comes last";
}

TEST(CellIoSequence, AnEstopRefusesThePrepareBeforeAnythingIsSwitchedOn) {
  Cell cell;
  cell.plc->set_input(MemoryPlc::kInputEstopOk, false);
  auto r = cell.io->prepare_cut();
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, LinkErrorCode::interlock);
  EXPECT_NE(r.error().message.find("e-stop"), std::string::npos) << r.error().message;
  // Only the safe direction: pump, abrasive and jet written off together (fail()), nothing on.
  EXPECT_EQ(cell.plc->writes(), (std::vector<std::string>{"coil 0 = 0", "coil 1 = 0", "coil 2 = 0"}));
}

TEST(CellIoSequence, FinishClosesTheJetThenAbrasiveThenPump) {
  Cell cell;
  ASSERT_TRUE(cell.io->prepare_cut());
  const std::size_t before = cell.plc->writes().size();
  ASSERT_TRUE(cell.io->finish_cut());
  std::vector<std::string> after;
  for (std::size_t i = before; i < cell.plc->writes().size(); ++i)
    if (cell.plc->writes()[i] != "heartbeat") after.push_back(cell.plc->writes()[i]);
  EXPECT_EQ(after, (std::vector<std::string>{"coil 2 = 0", "coil 1 = 0", "coil 0 = 0"}));
}

}  // namespace
}  // namespace lamina::drivers::testing
