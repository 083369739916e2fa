// What our posts emit, cut by the simulator: the knob's smallest sheet planned by the `lamina`
// CLI, streamed to the grbl personality by character counting (grblHAL post) and drip-fed to
// the xonxoff personality (Fanuc post). The execution log must repeat the program line for
// line, and the machine's time for it must agree with the planner's estimate.
#include <gtest/gtest.h>

#include <cstdlib>

#include "grbl_client.hpp"
#include "sim_process.hpp"

namespace lamina::sim::testing {
namespace {

struct PlannedSheet {
  std::vector<std::string> lines;  // the program as written, without blank lines
  double estimated_time_s = 0;
};

PlannedSheet plan_knob_sheet(const TempDir& dir, const std::string& post, int sheet) {
  const std::string out = dir.file(post);
  const std::string command = fmt::format("'{}' plan '{}/knob.stl' --stock-file '{}/remnants.toml' --post {} --out '{}' "
                                          "> '{}.log' 2>&1",
                                          LAMINA_CLI, LAMINA_EXAMPLES_DIR, LAMINA_EXAMPLES_DIR, post, out, out);
  if (std::system(command.c_str()) != 0) throw std::runtime_error("lamina plan failed: " + command);
  PlannedSheet p;
  std::ifstream program(fmt::format("{}/sheet-{}.nc", out, sheet));
  for (std::string line; std::getline(program, line);) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (!line.empty()) p.lines.push_back(line);
  }
  const auto report = nlohmann::json::parse(std::ifstream(out + "/report.json"));
  for (const auto& s : report["sheets"])
    if (s["index"] == sheet) p.estimated_time_s = s["estimated_time_s"];
  return p;
}

// The log's blocks against the program's lines (the `%` framing is not a block).
void expect_log_repeats_program(const std::vector<nlohmann::json>& blocks, const std::vector<std::string>& program) {
  std::vector<std::string> expected;
  for (const auto& line : program)
    if (line != "%") expected.push_back(line);
  ASSERT_EQ(blocks.size(), expected.size());
  for (std::size_t i = 0; i < expected.size(); ++i) {
    ASSERT_EQ(blocks[i]["line"], expected[i]) << "block " << i + 1;
    ASSERT_EQ(blocks[i].value("completed", true), true) << "block " << i + 1;
  }
}

// Time the machine spent on the blocks (not the gaps when the link could not keep up with a
// machine running 100 times faster than real time).
double machine_time_s(const std::vector<nlohmann::json>& blocks) {
  double t = 0;
  for (const auto& b : blocks) t += b["t_end"].get<double>() - b["t_start"].get<double>();
  return t;
}

constexpr double kTimeScale = 100;

TEST(SimRunsOurPosts, GrblhalProgramStreamedByCharacterCounting) {
  TempDir dir;
  const PlannedSheet sheet = plan_knob_sheet(dir, "grblhal", 4);
  ASSERT_GT(sheet.lines.size(), 100u);
  SimProcess sim({"--link", dir.file("cnc"), "--log", dir.file("exec.jsonl"), "--control", "127.0.0.1:0",
                  "--time-scale", fmt::format("{}", kTimeScale)});
  StreamClient c = StreamClient::open_pty(dir.file("cnc"));
  ASSERT_TRUE(wait_controller(c));
  const StreamResult r = stream_counting(c, sheet.lines, kGrblHalRxBytes, 120);
  ASSERT_TRUE(r.finished) << r.oks << " of " << sheet.lines.size();
  ASSERT_TRUE(r.errors.empty()) << r.errors.front();
  ASSERT_TRUE(wait_status(sim.control_port(), [&](const nlohmann::json& st) {
    return st["executed_blocks"] == st["accepted_blocks"] && st["state"] == "idle";
  }, 60));
  const auto blocks = executed_blocks(read_log(dir.file("exec.jsonl")));
  expect_log_repeats_program(blocks, sheet.lines);
  const double t = machine_time_s(blocks);
  RecordProperty("machine_time_s", std::to_string(t));
  RecordProperty("estimated_time_s", std::to_string(sheet.estimated_time_s));
  EXPECT_NEAR(t, sheet.estimated_time_s, 0.05 * sheet.estimated_time_s) << "the planner's estimate vs the machine";
}

TEST(SimRunsOurPosts, FanucProgramDripFedWithXonXoff) {
  TempDir dir;
  const PlannedSheet sheet = plan_knob_sheet(dir, "fanuc", 4);
  ASSERT_EQ(sheet.lines.front(), "%");
  SimProcess sim({"--personality", "xonxoff", "--link", dir.file("cnc"), "--log", dir.file("exec.jsonl"),
                  "--control", "127.0.0.1:0", "--time-scale", fmt::format("{}", kTimeScale), "--rx-buffer", "512"});
  StreamClient c = StreamClient::open_pty(dir.file("cnc"));
  std::string text;
  for (const auto& line : sheet.lines) text += line + "\n";
  bool paused = false;
  std::size_t sent = 0, seen = 0;
  const auto t0 = std::chrono::steady_clock::now();
  while (sent < text.size() && seconds_since(t0) < 120) {
    c.read_until([](const std::string&) { return false; }, paused ? 0.005 : 0.0);
    for (; seen < c.buffer().size(); ++seen) {
      if (c.buffer()[seen] == 0x13) paused = true;
      if (c.buffer()[seen] == 0x11) paused = false;
      ASSERT_NE(c.buffer()[seen], 0x15) << "NAK: the controller alarmed";
    }
    if (paused) continue;
    const std::size_t n = std::min<std::size_t>(16, text.size() - sent);
    c.send(text.substr(sent, n));
    sent += n;
    std::this_thread::sleep_for(std::chrono::microseconds(n * 1'000'000 / 11'520));  // paced to the wire
  }
  ASSERT_EQ(sent, text.size());
  ASSERT_TRUE(wait_status(sim.control_port(), [&](const nlohmann::json& st) {
    return st["executed_blocks"] == st["accepted_blocks"] && st["state"] == "idle" &&
           st["lines_received"].get<std::size_t>() >= sheet.lines.size() - 2;  // all but the two %
  }, 60));
  const auto blocks = executed_blocks(read_log(dir.file("exec.jsonl")));
  expect_log_repeats_program(blocks, sheet.lines);
  EXPECT_NEAR(machine_time_s(blocks), sheet.estimated_time_s, 0.05 * sheet.estimated_time_s);
}

}  // namespace
}  // namespace lamina::sim::testing
