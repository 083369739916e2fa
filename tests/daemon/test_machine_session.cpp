// MachineSession's status as machine.status shows it (issue 16, item 4): what the PLC cannot
// tell any more reads as unknown (null), not as its last values.
#include <gtest/gtest.h>

#include <fmt/format.h>

#include <functional>
#include <thread>

#include "machine_session.hpp"
#include "sim_process.hpp"

namespace lamina::daemon {
namespace {

using sim::testing::SimProcess;
using sim::testing::TempDir;

TEST(MachineSessionStatus, AnUnreachablePlcReadsAsUnknownNotAsItsLastValues) {
  TempDir dir;
  auto sim = std::make_unique<SimProcess>(std::vector<std::string>{"--link", dir.file("cnc"), "--modbus", "127.0.0.1:0"});
  DaemonConfig config;
  config.link.port = dir.file("cnc");
  config.cell.modbus = fmt::format("127.0.0.1:{}", sim->modbus_port());
  config.cell.modbus_reconnects = 0;
  MachineSession session(config);
  ASSERT_NE(session.cell(), nullptr);
  ASSERT_TRUE(session.cell()->refresh());
  nlohmann::json cell = session.status()["cell"];
  EXPECT_EQ(cell["connected"], true);
  EXPECT_TRUE(cell["estop_ok"].is_boolean()) << cell.dump();
  EXPECT_TRUE(cell["pressure_mpa"].is_number()) << cell.dump();

  sim.reset();  // the PLC is gone (power, cable)
  EXPECT_FALSE(session.cell()->refresh());
  cell = session.status()["cell"];
  EXPECT_EQ(cell["connected"], false) << cell.dump();
  for (const char* key : {"estop_ok", "door_closed", "pump_ready", "jet_is_on", "pressure_mpa", "abrasive_g_per_min",
                          "alarm_latched", "alarm_code"})
    EXPECT_TRUE(cell[key].is_null()) << key << " still shows a value the PLC can no longer confirm: " << cell.dump();
  EXPECT_TRUE(cell["read_age_s"].is_number()) << "how old the last reading is";
}

// Between cuts the PLC used to be read only on request: machine.status showed e-stop and door
// as the last cut left them, with their age. Now it is read every [cell] idle_poll_s.
TEST(MachineSessionStatus, BetweenCutsThePlcIsReadOnItsOwn) {
  TempDir dir;
  SimProcess sim({"--link", dir.file("cnc"), "--modbus", "127.0.0.1:0", "--control", "127.0.0.1:0"});
  DaemonConfig config;
  config.link.port = dir.file("cnc");
  config.cell.modbus = fmt::format("127.0.0.1:{}", sim.modbus_port());
  config.cell.idle_poll_s = 0.1;
  MachineSession session(config);
  const auto wait_cell = [&](const std::function<bool(const nlohmann::json&)>& ready) {
    for (int i = 0; i < 500; ++i) {
      if (ready(session.status()["cell"])) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    return false;
  };
  EXPECT_TRUE(wait_cell([](const nlohmann::json& c) { return c["estop_ok"] == true; }))
      << "read without a cut or a request: " << session.status()["cell"].dump();
  sim::testing::control(sim.control_port(), "estop on");
  EXPECT_TRUE(wait_cell([](const nlohmann::json& c) { return c["estop_ok"] == false; }))
      << "the e-stop pressed between cuts shows: " << session.status()["cell"].dump();
  EXPECT_LT(session.status()["cell"]["read_age_s"].get<double>(), 2.0);
}

}  // namespace
}  // namespace lamina::daemon
