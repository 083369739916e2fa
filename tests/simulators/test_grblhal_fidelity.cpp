// Issue 15: where lamina-sim differed from the real grblHAL and so hid a streamer bug. One test
// (or a few) per row of the issue's table, each failing on the simulator before the fix. The
// grblHAL function each behaviour follows is named in the simulator's comments and in
// docs/simulator.md.
#include <gtest/gtest.h>

#include <regex>
#include <string>

#include "grbl_protocol.hpp"
#include "protocol_harness.hpp"
#include "sim_options.hpp"

namespace lamina::sim {
namespace {

using test::count_of;
using test::ProtocolHarness;

struct FidelityGrbl : ProtocolHarness {
  explicit FidelityGrbl(MachineConfig config = {}, GrblParams params = {}) : ProtocolHarness(std::move(config)) {
    protocol = make_grbl_protocol(machine, params);
    protocol->on_connect(now_s);
    take();  // the banner
  }
  std::string status() {
    send("?");
    return take();
  }
};

std::string state_of(const std::string& report) {
  static const std::regex re(R"(<([A-Za-z:0-9]+)\|)");
  std::smatch m;
  return std::regex_search(report, m, re) ? std::string(m[1]) : std::string();
}
std::string field(const std::string& report, const std::string& name) {
  const std::regex re("\\|" + name + ":([^|>]*)");
  std::smatch m;
  return std::regex_search(report, m, re) ? std::string(m[1]) : std::string("<none>");
}

// --- G4: a dwell waits for the motion, dwells in Idle with every block free, and its ok comes
// after it (mc_dwell: protocol_buffer_synchronize, then delay_sec) ---

TEST(GrblHalFidelity, DwellAnswersOkOnlyWhenItEndsAndReportsIdleWithEveryBlockFree) {
  FidelityGrbl g;
  g.send("G1X10F600\nG4P3\nG1X20\n");  // 1 s of motion, then 3 s of dwell
  EXPECT_EQ(count_of(g.take(), "ok"), 1) << "the dwell waits for the motion before it";
  g.run_for(2.0);  // 1 s into the dwell
  EXPECT_EQ(count_of(g.take(), "ok"), 0) << "no ok while dwelling";
  const std::string dwelling = g.status();
  EXPECT_EQ(state_of(dwelling), "Idle") << dwelling;
  // Every planner block free; the line behind the dwell (6 bytes) still in the receive buffer.
  EXPECT_EQ(field(dwelling, "Bf"), "100,1017") << dwelling;
  EXPECT_EQ(field(dwelling, "Ln"), "<none>");
  g.run_for(1.9);  // t = 3.9 s: 0.1 s of dwell left
  EXPECT_EQ(count_of(g.take(), "ok"), 0);
  g.run_for(0.2);
  EXPECT_EQ(g.take(), "ok\r\nok\r\n") << "the dwell's ok, then the line behind it";
  EXPECT_EQ(state_of(g.status()), "Run");
}

TEST(GrblHalFidelity, FeedHoldPausesADwellAndItsOk) {
  FidelityGrbl g;
  g.send("G4P2\n");
  g.run_for(0.5);
  g.send("!");
  EXPECT_EQ(state_of(g.status()), "Hold:0");
  g.run_for(5.0);  // held: the dwell clock stands
  EXPECT_EQ(count_of(g.take(), "ok"), 0);
  g.send("~");
  g.run_for(1.4);
  EXPECT_EQ(count_of(g.take(), "ok"), 0) << "1.5 s of the dwell were left";
  g.run_for(0.2);
  EXPECT_EQ(g.take(), "ok\r\n");
}

TEST(GrblHalFidelity, ResetDuringADwellDropsItsLineUnanswered) {
  FidelityGrbl g;
  g.send("G4P2\nG0X5\n");
  g.run_for(0.5);
  g.send("\x18");
  const std::string out = g.take();
  EXPECT_EQ(count_of(out, "ok"), 0) << out;
  EXPECT_NE(out.find("GrblHAL"), std::string::npos) << "the banner follows: " << out;
  EXPECT_EQ(out.find("ALARM"), std::string::npos) << "no motion was lost: " << out;
  g.run_for(3.0);
  EXPECT_EQ(count_of(g.take(), "ok"), 0) << "the line behind it went with the buffer";
}

TEST(GrblHalFidelity, TheExecutionLogListsADwellOnceWhenItEnds) {
  FidelityGrbl g;
  g.send("G0X10\nG4P1\nM3\nG1X20F600\nM5\nM30\n");
  g.run_for(5.0);
  const std::vector<std::string> expected{"G0X10", "G4P1", "M3", "G1X20F600", "M5", "M30"};
  EXPECT_EQ(g.executed_lines(), expected);
  EXPECT_EQ(g.machine.starvation_count(), 0u) << "the lines behind the dwell waited for it, not the host";
}

// --- Bf: the receive field is at most size − 1 (serialRxFree), [OPT:] still names the size ---

TEST(GrblHalFidelity, ReceiveBufferReportsSizeMinusOneFreeAndOptTheSize) {
  FidelityGrbl g;
  EXPECT_EQ(field(g.status(), "Bf"), "100,1023");
  g.send("$I\n");
  EXPECT_NE(g.take().find("[OPT:VNL,100,1024,5,0]"), std::string::npos);
  GrblParams small;
  small.rx_buffer_bytes = 16;
  FidelityGrbl s({}, small);
  s.send_burst("G1X1234567890123");  // 16 bytes, no end of line: the 16th is lost
  EXPECT_EQ(s.protocol->counters().bytes_received, 15u);
  EXPECT_EQ(s.protocol->counters().bytes_dropped, 1u);
}

// --- M2 / M30: [MSG:Pgm End] before the ok (gc_execute_block, Message_ProgramEnd) ---

TEST(GrblHalFidelity, ProgramEndSaysPgmEndThenOk) {
  FidelityGrbl g;
  g.send("M30\n");
  EXPECT_EQ(g.take(), "[MSG:Pgm End]\r\nok\r\n");
  g.send("G1X1F600\nM2\n");
  EXPECT_EQ(g.take(), "ok\r\n") << "M2 waits for the motion (the planner sync)";
  g.run_for(1.0);
  EXPECT_EQ(g.take(), "[MSG:Pgm End]\r\nok\r\n");
}

// --- M3/M4/M5, M7/M8/M9: accepted without S, shown in the accessory field A: ---

TEST(GrblHalFidelity, SpindleAndCoolantShowInTheAccessoryField) {
  FidelityGrbl g;
  g.status();  // the first report after the banner carries Ov (and A: with it)
  g.send("M3\n");
  EXPECT_EQ(g.take(), "ok\r\n") << "M3 without S";
  EXPECT_EQ(field(g.status(), "A"), "S") << "reported in the report after the change";
  EXPECT_EQ(field(g.status(), "A"), "<none>") << "then only with the Ov refresh";
  g.send("M8\n");
  g.take();
  EXPECT_EQ(field(g.status(), "A"), "SF");
  g.send("M7\n");
  g.take();
  EXPECT_EQ(field(g.status(), "A"), "SFM");
  g.send("M9\nM5\n");
  EXPECT_EQ(g.take(), "ok\r\nok\r\n");
  EXPECT_EQ(field(g.status(), "A"), "") << "an empty A: says everything went off";
  g.send("M4\n");
  g.take();
  EXPECT_EQ(field(g.status(), "A"), "C") << "counter-clockwise";
  EXPECT_TRUE(g.machine.jet_commanded()) << "M4 is the jet too";
  g.send("$G\n");
  EXPECT_NE(g.take().find(" M4 M9 "), std::string::npos);
}

// --- A letter the machine has no axis for: error:36 (grblHAL keeps it as a parameter word,
// then "[Unused words]") ---

TEST(GrblHalFidelity, BWordOnAnXyzacMachineIsErrorThirtySix) {
  FidelityGrbl g;
  g.send("G1X1B10F100\n");
  EXPECT_EQ(g.take(), "error:36\r\n");
  Machine m({});
  EXPECT_EQ(m.submit_line("G1X1B10", 0), GrblStatus::undefined_feed_rate) << "grblHAL's other checks come first";
  EXPECT_EQ(m.submit_line("B10", 0), GrblStatus::unused_words);
}

// --- M7 M8 M9 M4, G53, G28: accepted, and they do what grblHAL does ---

TEST(GrblHalFidelity, CoolantAndCounterClockwiseSpindleCodesAreAccepted) {
  FidelityGrbl g;
  g.send("M7\nM8\nM9\nM4\nM5\n");
  EXPECT_EQ(g.take(), "ok\r\nok\r\nok\r\nok\r\nok\r\n");
}

TEST(GrblHalFidelity, G53MovesInMachineCoordinatesEvenInIncrementalMode) {
  FidelityGrbl g;
  g.send("G0X10\nG91\nG53G0X50Y5\nG0X1\n");
  EXPECT_EQ(g.take(), "ok\r\nok\r\nok\r\nok\r\n");
  g.run_for(1.0);
  EXPECT_NEAR(g.machine.position(g.now_s)[0], 51, 1e-9) << "G53 went to X50 absolute, then G91 X+1";
  EXPECT_NEAR(g.machine.position(g.now_s)[1], 5, 1e-9);
  g.send("G2X1Y1I1G53\n");
  EXPECT_EQ(g.take(), "error:30\r\n") << "G53 only with G0/G1";
}

TEST(GrblHalFidelity, G28GoesViaTheIntermediatePointToMachineZero) {
  MachineConfig config;
  Machine m(config);
  ASSERT_EQ(m.submit_line("G0X100Y50Z-10", 0), GrblStatus::ok);
  m.advance(1);
  ASSERT_EQ(m.submit_line("G28Z0", 1), GrblStatus::ok);  // via Z0, then Z home; X and Y stay
  m.advance(5);
  EXPECT_EQ(m.position(5), (AxisValues{100, 50, 0, 0, 0}));
  ASSERT_EQ(m.submit_line("G0Z-20", 5), GrblStatus::ok);
  ASSERT_EQ(m.submit_line("G28", 5), GrblStatus::ok);  // no axis words: every axis home, straight
  m.advance(10);
  EXPECT_EQ(m.position(10), (AxisValues{0, 0, 0, 0, 0}));
  std::vector<ExecutedBlock> done;
  for (const auto& e : m.take_events())
    if (const auto* b = std::get_if<ExecutedBlock>(&e)) done.push_back(*b);
  ASSERT_EQ(done.size(), 4u);
  // Z from -10 up to 0 and on to 0: 10 mm at the Z rapid of 5000 mm/min.
  EXPECT_NEAR(done[1].t_end_s - done[1].t_start_s, 10.0 / 5000 * 60, 1e-9);
  // No axis words: straight home from (100, 50, -20); the X rapid (100 mm) sets the time.
  EXPECT_NEAR(done[3].t_end_s - done[3].t_start_s, 100.0 / 20000 * 60, 1e-9);
  EXPECT_EQ(m.submit_line("G28G0X1", 10), GrblStatus::axis_command_conflict);

  config.g28_position = {10, 20, 0, 0, 0};
  Machine stored(config);
  ASSERT_EQ(stored.submit_line("G28X5", 0), GrblStatus::ok);  // via X5 to the stored X10
  stored.advance(10);
  EXPECT_EQ(stored.position(10), (AxisValues{10, 0, 0, 0, 0}));
}

// --- G2/G3: forms grblHAL accepts that the simulator refused ---

TEST(GrblHalFidelity, ArcFormsGrblHalAccepts) {
  Machine m({});
  // R arc whose ends meet in XY while Z moves: grblHAL's invalid-target check compares the
  // whole position vector, so it is no error there (the arc degenerates to its final line).
  EXPECT_EQ(m.submit_line("G2X0Y0Z-5R10F600", 0), GrblStatus::ok);
  // K beside I/J in the XY plane: consumed by offset mode, not an unused word.
  EXPECT_EQ(m.submit_line("G2X20Y0I10J0K0", 0), GrblStatus::ok);
  m.advance(100);
  // Still refused, with grblHAL's codes.
  EXPECT_EQ(m.submit_line("G2X20Y0Z-5R10", 100), GrblStatus::invalid_target) << "same point on every axis";
  EXPECT_EQ(m.submit_line("G2X0Y0", 100), GrblStatus::no_offsets_in_plane);
  EXPECT_EQ(m.submit_line("G2Z-1I5", 100), GrblStatus::no_axis_words_in_plane);
  EXPECT_EQ(m.submit_line("G2X30Y0I3", 100), GrblStatus::invalid_target) << "end not on the circle";
}

// --- Status fields: WCO and Ov every N reports (report.c's counters), A: with Ov or on change ---

TEST(GrblHalFidelity, WcoAndOverridesComeEveryFewReportsAsGrblHalCountsThem) {
  FidelityGrbl g;
  std::vector<std::string> reports;
  for (int i = 0; i < 23; ++i) reports.push_back(g.status());
  auto has = [&](int n, const char* name) { return field(reports[static_cast<std::size_t>(n - 1)], name) != "<none>"; };
  // Idle: Ov in the first report after the banner, WCO when its counter of 10 runs out, and Ov
  // one report after a WCO (never beside it).
  EXPECT_TRUE(has(1, "Ov")) << reports[0];
  EXPECT_EQ(field(reports[0], "Ov"), "100,100,100");
  for (int n = 2; n <= 10; ++n) {
    EXPECT_FALSE(has(n, "Ov")) << n;
    EXPECT_FALSE(has(n, "WCO")) << n;
  }
  EXPECT_TRUE(has(11, "WCO")) << reports[10];
  EXPECT_EQ(field(reports[10], "WCO"), "0.000,0.000,0.000,0.000,0.000");
  EXPECT_FALSE(has(11, "Ov"));
  EXPECT_TRUE(has(12, "Ov")) << reports[11];
  EXPECT_TRUE(has(21, "WCO")) << reports[20];
  EXPECT_TRUE(has(22, "Ov")) << reports[21];
  for (const auto& r : reports) {
    EXPECT_EQ(field(r, "H"), "<none>") << "homing is disabled ($22=0)";
    EXPECT_EQ(field(r, "TLR"), "<none>") << "no tool length reference";
    EXPECT_EQ(field(r, "A"), "<none>") << "nothing on, nothing changed";
  }
}

TEST(GrblHalFidelity, AccessoriesRideWithTheOverridesAndProgramEndFlagsWco) {
  FidelityGrbl g;
  g.send("M3\n");
  g.take();
  const std::string first = g.status();
  EXPECT_EQ(field(first, "Ov"), "100,100,100");
  EXPECT_EQ(field(first, "A"), "S");
  for (int i = 0; i < 8; ++i) g.status();
  g.send("M30\n");
  g.take();
  const std::string after_end = g.status();
  EXPECT_EQ(field(after_end, "WCO"), "0.000,0.000,0.000,0.000,0.000") << "the program end's wco flag: " << after_end;
  EXPECT_EQ(field(after_end, "A"), "") << "and its spindle off: " << after_end;
}

// --- The default soft limits run Lamina's own programs (pivot coordinates below zero) ---

TEST(GrblHalFidelity, DefaultSoftLimitsAreTheSimMachineFiles) {
  SimOptions from_file;
  from_file.machine.soft_min = {};
  from_file.machine.soft_max = {};
  apply_machine_file(std::string(LAMINA_DOCS_DIR) + "/../config/sim-machine.toml", from_file);
  const MachineConfig defaults;
  EXPECT_EQ(defaults.soft_min, from_file.machine.soft_min);
  EXPECT_EQ(defaults.soft_max, from_file.machine.soft_max);
  Machine m(defaults);
  // A tilted head's pivot beside and above the table's corner, as the knob's sheets have it.
  EXPECT_EQ(m.submit_line("G0X-130Y-130Z150A60C45", 0), GrblStatus::ok);
  EXPECT_FALSE(m.alarm());
}

}  // namespace
}  // namespace lamina::sim
