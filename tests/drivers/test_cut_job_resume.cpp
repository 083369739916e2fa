// A stopped cut waits for the operator; resume() restarts at the start of the contour that was
// being cut, so every finished contour runs exactly once and the program completes.
#include <gtest/gtest.h>

#include <thread>

#include "lamina/drivers/cell_io.hpp"
#include "lamina/drivers/cut_job.hpp"
#include "lamina/drivers/modbus_block_link.hpp"
#include "lamina/drivers/streamer.hpp"
#include "link_test_support.hpp"
#include "pty_link.hpp"

namespace lamina::drivers::testing {
namespace {

struct Record {
  std::string line;
  bool completed;
};

std::vector<Record> records(const std::string& log) {
  std::vector<Record> out;
  for (const auto& r : sim::testing::executed_blocks(sim::testing::read_log(log)))
    out.push_back({r["line"], r.value("completed", true)});
  return out;
}

std::size_t contour_start_at_or_before(const std::vector<std::string>& program, std::size_t index) {
  std::size_t start = 0;
  for (std::size_t i = 0; i <= index && i < program.size(); ++i)
    if (program[i].rfind("(CONTOUR ", 0) == 0) start = i;
  return start;
}

// The log of a run that stopped once and was resumed: the first run's blocks, the resume
// preamble (…, "G94", "G0Z10"), then the program from the restart line to its end.
void expect_resumed_once_from_contour_start(const std::vector<Record>& log, const std::vector<std::string>& program,
                                            std::size_t restart) {
  std::size_t preamble = log.size();
  for (std::size_t i = 0; i + 1 < log.size(); ++i)
    if (log[i].line == "G94" && log[i + 1].line.rfind("G0Z", 0) == 0) preamble = i;
  ASSERT_LT(preamble, log.size()) << "no resume preamble in the log";
  ASSERT_GE(preamble, 1u);
  // First run: the program in order; the lines that completed end where the stop came.
  std::size_t done = 0;
  for (std::size_t i = 0; i + 1 < preamble; ++i) {
    ASSERT_EQ(log[i].line, program[i]) << "first run, block " << i + 1;
    if (log[i].completed) done = i + 1;
  }
  EXPECT_EQ(log[preamble - 1].line, "G21G90G94G17") << "the program's modal set-up starts the preamble";
  // Restart at the start of the contour holding the first line that had not finished.
  EXPECT_EQ(restart, contour_start_at_or_before(program, done)) << "first unfinished line " << done + 1;
  const std::size_t after = preamble + 2;
  ASSERT_EQ(log.size() - after, program.size() - restart);
  for (std::size_t i = 0; i < program.size() - restart; ++i) {
    EXPECT_EQ(log[after + i].line, program[restart + i]) << "resumed block " << i + 1;
    EXPECT_TRUE(log[after + i].completed);
  }
  // No contour that had finished runs twice: the resumed part begins inside the stopped one.
  EXPECT_GT(done, restart - 1);
}

TEST(CutJobResume, AfterAnAlarmOnlyTheOperatorResumesFromTheContourStart) {
  TempDir dir;
  const auto program = contour_program(4, 100);
  SimProcess sim({"--link", dir.file("cnc"), "--log", dir.file("exec.jsonl"), "--control", "127.0.0.1:0",
                  "--alarm-at-line", "260", "--time-scale", "4"});
  auto link = grbl_pty_link(dir.file("cnc"));
  CutJob job(*link, nullptr, program);
  CutReport r = job.run();
  ASSERT_EQ(r.state, CutState::stopped);
  ASSERT_TRUE(r.reason);
  EXPECT_EQ(r.reason->code, LinkErrorCode::controller_alarm) << r.reason->message;
  ASSERT_TRUE(r.resume);
  // Nothing happens until the operator says so.
  const auto before = records(dir.file("exec.jsonl")).size();
  std::this_thread::sleep_for(std::chrono::seconds(1));
  EXPECT_EQ(records(dir.file("exec.jsonl")).size(), before);
  EXPECT_EQ(job.report().state, CutState::stopped);

  const std::size_t restart = r.resume->restart_index;
  r = job.resume();
  ASSERT_EQ(r.state, CutState::completed) << (r.reason ? r.reason->message : "");
  expect_resumed_once_from_contour_start(records(dir.file("exec.jsonl")), program, restart);
}

TEST(CutJobResume, AfterAFeedHoldStopTheQueueTellsExactlyWhatRan) {
  TempDir dir;
  const auto program = contour_program(4, 100);
  SimProcess sim({"--link", dir.file("cnc"), "--log", dir.file("exec.jsonl"), "--control", "127.0.0.1:0",
                  "--time-scale", "2"});
  auto link = grbl_pty_link(dir.file("cnc"));
  CutJob job(*link, nullptr, program);
  std::thread stopper([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(2500));  // well into the second contour
    job.abort("operator stop");
  });
  CutReport r = job.run();
  stopper.join();
  ASSERT_EQ(r.state, CutState::stopped);
  EXPECT_EQ(r.reason->code, LinkErrorCode::cancelled);
  ASSERT_TRUE(r.last_status);
  EXPECT_EQ(r.last_status->state, ControllerState::hold) << "held with its queue intact";
  ASSERT_TRUE(r.resume);
  const std::size_t restart = r.resume->restart_index;
  EXPECT_GT(restart, 0u);
  r = job.resume();
  ASSERT_EQ(r.state, CutState::completed) << (r.reason ? r.reason->message : "");
  expect_resumed_once_from_contour_start(records(dir.file("exec.jsonl")), program, restart);
}

}  // namespace
}  // namespace lamina::drivers::testing

namespace lamina::drivers::testing {
namespace {

// A controller without a status report of its own (a drip feed) or fed through the PLC: the
// PLC's count of executed blocks places the stop, its buttons hold and reset the CNC.
void pressure_drop_then_resume(const std::string& protocol) {
  TempDir dir;
  const auto program = contour_program(4, 100);
  std::vector<std::string> args{"--link", dir.file("cnc"), "--log", dir.file("exec.jsonl"), "--control", "127.0.0.1:0",
                                "--modbus", "127.0.0.1:0", "--pressure-ramp", "0.2", "--time-scale", "2"};
  if (protocol == "xonxoff")
    args.insert(args.end(), {"--personality", "xonxoff", "--rx-buffer", "256", "--planner-blocks", "8"});
  SimProcess sim(args);
  std::unique_ptr<MachineLink> link;
  if (protocol == "xonxoff") {
    StreamerSettings settings;
    settings.status_period_s = 0;
    settings.pace_bytes_per_s = 11520;
    const std::string path = dir.file("cnc");
    link = std::make_unique<Streamer>(
        [path](boost::asio::io_context& io) { return open_serial(io, path, SerialSettings{}); },
        make_xonxoff_protocol(), settings);
  } else {
    ModbusBlockSettings settings;
    settings.plc.port = sim.modbus_port();
    link = std::make_unique<ModbusBlockLink>(settings);
  }
  CellIoSettings cell_settings;
  cell_settings.plc.port = sim.modbus_port();
  CellIo cell(cell_settings);
  CutJobSettings job_settings;
  job_settings.wait_for_idle = protocol != "xonxoff";
  CutJob job(*link, &cell, program, job_settings);
  std::thread fault([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(2000));
    sim::testing::control(sim.control_port(), "pressure drop");
  });
  CutReport r = job.run();
  fault.join();
  ASSERT_EQ(r.state, CutState::stopped) << (r.reason ? r.reason->message : "");
  EXPECT_EQ(r.reason->code, LinkErrorCode::interlock) << r.reason->message;
  ASSERT_TRUE(r.resume);
  EXPECT_GT(r.first_unfinished_line, 0u) << "the PLC's executed count placed the stop";
  const std::size_t restart = r.resume->restart_index;
  EXPECT_EQ(sim::testing::control(sim.control_port(), "pressure restore"), "ok");
  r = job.resume();
  ASSERT_EQ(r.state, CutState::completed) << (r.reason ? r.reason->message : "");
  ASSERT_TRUE(sim::testing::wait_status(sim.control_port(), [](const nlohmann::json& st) {
    return st["queued_blocks"] == 0 && st["state"] == "idle";
  }, 60));
  expect_resumed_once_from_contour_start(records(dir.file("exec.jsonl")), program, restart);
}

// A host that dies mid-program (laminad killed) leaves the controller draining its queue: the
// acks of the lines it still had in its receive buffer keep coming after a new host opened the
// port. They are not answers to the new host; it ignores them until the line goes quiet, then
// streams its own program, which runs after the old one, every line once.
TEST(CutJobResume, ANewHostIgnoresTheAcksMeantForTheOneThatDied) {
  TempDir dir;
  SimProcess sim({"--link", dir.file("cnc"), "--log", dir.file("exec.jsonl"), "--control", "127.0.0.1:0",
                  "--time-scale", "1"});
  std::vector<std::string> first{"G21G90G94"};  // 100 blocks fill the planner, 20 wait in the receive buffer
  for (int i = 0; i < 119; ++i) first.push_back(fmt::format("G1X{}F600", i % 2));  // 0.1 s each
  {
    auto dead_host = sim::testing::StreamClient::open_pty(dir.file("cnc"));
    std::string bytes;
    for (const auto& l : first) bytes += l + "\n";
    ASSERT_TRUE(dead_host.send(bytes));
    ASSERT_TRUE(sim::testing::wait_status(sim.control_port(), [](const nlohmann::json& st) {
      return st["queued_blocks"].get<int>() >= 90;
    }, 10));
  }  // closed without reading a byte
  const std::vector<std::string> second{"G0X20", "G1X21F600", "G1X22F600", "G0X0"};
  auto link = grbl_pty_link(dir.file("cnc"));
  link->start(LineSpan{second, 0}, {});
  const auto outcome = link->wait(30);
  ASSERT_TRUE(outcome);
  ASSERT_TRUE(outcome->completed) << outcome->error->message;
  // Had a stale ok ended the `$I` handshake, the window would be classic Grbl's 128 bytes and
  // the acks that followed would have been counted for our lines before they were taken.
  EXPECT_EQ(link->progress().rx_buffer_bytes, 1024) << "the window came from the controller's own [OPT:]";
  ASSERT_TRUE(sim::testing::wait_status(sim.control_port(), [](const nlohmann::json& st) {
    return st["queued_blocks"] == 0 && st["state"] == "idle";
  }, 30));
  const auto log = records(dir.file("exec.jsonl"));
  ASSERT_EQ(log.size(), first.size() + second.size());
  for (std::size_t i = 0; i < first.size(); ++i) ASSERT_EQ(log[i].line, first[i]) << "block " << i + 1;
  for (std::size_t i = 0; i < second.size(); ++i) ASSERT_EQ(log[first.size() + i].line, second[i]);
}

// The CNC's cable is pulled mid-cut and put back (issue 16, item 7): the stop is safe (the PLC
// holds the machine, jet off), and the operator's resume opens the port again before its reset
// — it used to reset over the closed port and fail with "no banner after the soft reset".
TEST(CutJobResume, AfterAnUnplugAndReplugTheResumeOpensThePortAgain) {
  TempDir dir;
  const auto program = contour_program(4, 100);
  SimProcess sim({"--link", dir.file("cnc"), "--log", dir.file("exec.jsonl"), "--control", "127.0.0.1:0",
                  "--modbus", "127.0.0.1:0", "--pressure-ramp", "0.2", "--time-scale", "2"});
  auto link = grbl_pty_link(dir.file("cnc"));
  CellIoSettings cell_settings;
  cell_settings.plc.port = sim.modbus_port();
  CellIo cell(cell_settings);
  CutJob job(*link, &cell, program);
  std::thread fault([&] {
    sim::testing::wait_status(sim.control_port(), [](const nlohmann::json& st) { return st["executed_blocks"] > 150; }, 30);
    sim::testing::control(sim.control_port(), "unplug");
  });
  CutReport r = job.run();
  fault.join();
  ASSERT_EQ(r.state, CutState::stopped) << (r.reason ? r.reason->message : "");
  EXPECT_EQ(r.reason->code, LinkErrorCode::io_error) << r.reason->message;
  ASSERT_TRUE(r.resume);
  ASSERT_EQ(sim::testing::control(sim.control_port(), "replug"), "ok");
  ASSERT_TRUE(sim::testing::wait_status(sim.control_port(), [](const nlohmann::json& st) { return st["plugged"] == true; }, 10));
  const std::size_t restart = r.resume->restart_index;
  r = job.resume();
  ASSERT_EQ(r.state, CutState::completed) << (r.reason ? r.reason->message : "");
  // The resumed run is the program from the restart contour to its end, every line once.
  const auto log = records(dir.file("exec.jsonl"));
  ASSERT_GE(log.size(), program.size() - restart);
  const std::size_t tail = log.size() - (program.size() - restart);
  for (std::size_t i = 0; i < program.size() - restart; ++i) EXPECT_EQ(log[tail + i].line, program[restart + i]);
}

TEST(CutJobResume, DripFeedStoppedByThePlcResumesFromTheContourStart) { pressure_drop_then_resume("xonxoff"); }
TEST(CutJobResume, MailboxStoppedByThePlcResumesFromTheContourStart) { pressure_drop_then_resume("modbus"); }

}  // namespace
}  // namespace lamina::drivers::testing
