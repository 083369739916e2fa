// CellIo against a Modbus server nobody here wrote: Debian's python3-pymodbus (3.0), serving a
// plain datastore with the map's sizes. What CellIo wrote is read back from that server.
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>

#include <fcntl.h>

#include <cstdlib>
#include <fstream>

#include "lamina/drivers/cell_io.hpp"
#include "modbus_test_client.hpp"

namespace lamina::drivers {
namespace {
using namespace testing;

// A passive PLC: estop_ok, door_closed and pump_ready pre-set, pressure 380 MPa; nothing reacts.
constexpr const char* kServerScript = R"PY(
import sys, types
try:
    import serial  # noqa: F401
except ImportError:  # pymodbus 3.0 imports pyserial at the top of its server module even for TCP
    sys.modules["serial"] = types.ModuleType("serial")
try:
    import serial_asyncio  # noqa: F401
except ImportError:  # … and pyserial-asyncio; only its serial servers use them
    stub = types.ModuleType("serial_asyncio")
    stub.create_serial_connection = None
    sys.modules["serial_asyncio"] = stub
from pymodbus.datastore import ModbusSequentialDataBlock, ModbusSlaveContext, ModbusServerContext
from pymodbus.server import StartTcpServer
port = int(sys.argv[1])
inputs = [0] * 6
inputs[0] = inputs[1] = inputs[2] = 1  # estop_ok, door_closed, pump_ready
ir = [0] * 20
ir[0] = 3800  # pressure 380 MPa
store = ModbusSlaveContext(co=ModbusSequentialDataBlock(0, [0] * 7), di=ModbusSequentialDataBlock(0, inputs),
                           hr=ModbusSequentialDataBlock(0, [0] * 112), ir=ModbusSequentialDataBlock(0, ir),
                           zero_mode=True)
print("serving", flush=True)
StartTcpServer(context=ModbusServerContext(slaves=store, single=True), address=("127.0.0.1", port))
)PY";

class PythonServer {
 public:
  // Its chatter (asyncio logs each closed connection as an error) goes to `log_path`.
  PythonServer(const std::string& script, int port, const std::string& log_path) {
    std::vector<std::string> args{"/usr/bin/python3", script, std::to_string(port)};
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, 1, log_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_adddup2(&actions, 1, 2);
    if (posix_spawn(&pid_, argv[0], &actions, nullptr, argv.data(), environ) != 0) pid_ = -1;
    posix_spawn_file_actions_destroy(&actions);
  }
  ~PythonServer() {
    if (pid_ <= 0) return;
    ::kill(pid_, SIGTERM);
    int status = 0;
    ::waitpid(pid_, &status, 0);
  }
  bool started() const { return pid_ > 0; }

 private:
  pid_t pid_ = -1;
};

TEST(CellIoPeer, PrepareCutAgainstPymodbusWritesTheCoils) {
  if (std::system("/usr/bin/python3 -c 'import pymodbus' >/dev/null 2>&1") != 0)
    GTEST_SKIP() << "python3-pymodbus is not installed (apt install python3-pymodbus)";
  TempDir dir;
  const std::string script = dir.file("plc.py");
  std::ofstream(script) << kServerScript;
  const int port = unused_port();
  PythonServer server(script, port, dir.file("server.log"));
  ASSERT_TRUE(server.started());
  std::unique_ptr<PlcProbe> probe;
  ASSERT_TRUE(eventually([&] {
    try {
      probe = std::make_unique<PlcProbe>(port);
      return true;
    } catch (const std::exception&) {
      return false;
    }
  }, 15.0)) << "the pymodbus server did not come up";

  CellIoSettings settings;
  settings.plc.port = port;
  settings.pump_ready_timeout_s = 2;
  auto io = std::make_unique<CellIo>(settings);
  auto r = io->prepare_cut();
  ASSERT_TRUE(r) << r.error().message;
  EXPECT_EQ(probe->coil(map::kCoilPump), 1);
  EXPECT_EQ(probe->coil(map::kCoilAbrasive), 1);
  EXPECT_EQ(probe->coil(map::kCoilJet), 1);
  EXPECT_EQ(probe->hold(0), 3800) << "pressure_setpoint";
  EXPECT_EQ(probe->hold(2), 350) << "abrasive_setpoint";
  const int beat = probe->hold(1);
  EXPECT_TRUE(eventually([&] { return probe->hold(1) != beat; }, 1.0)) << "heartbeat keeps changing";
  EXPECT_FALSE(io->fault());
  ASSERT_TRUE(io->finish_cut());
  EXPECT_EQ(probe->coil(map::kCoilJet), 0);
  EXPECT_EQ(probe->coil(map::kCoilAbrasive), 0);
  EXPECT_EQ(probe->coil(map::kCoilPump), 0);
}

}  // namespace
}  // namespace lamina::drivers
