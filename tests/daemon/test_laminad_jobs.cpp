// laminad end to end against lamina-sim: a job submitted over the socket is planned, each sheet
// confirmed as the operator would, streamed through the simulated CNC; the simulator's execution
// log is the programs, line for line. Hold/resume, abort + resume, cancel while planning.
#include <gtest/gtest.h>

#include "campaign_checks.hpp"
#include "daemon_fixture.hpp"
#include "modbus_test_client.hpp"

namespace lamina::daemon::testing {
namespace {

const std::string kModel = std::string(LAMINA_EXAMPLES_DIR) + "/knob.stl";
const std::string kRemnants = std::string(LAMINA_EXAMPLES_DIR) + "/remnants.toml";

bool wait_for_log_event(const Cell& cell, const std::string& kind, double wait_s) {
  const auto t0 = std::chrono::steady_clock::now();
  while (seconds_since(t0) < wait_s) {
    for (const auto& r : sim::testing::read_log(cell.log()))
      if (r.value("event", "") == kind) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return false;
}

// Confirms sheets as they come until the job completes (or stops being runnable).
Json run_to_completion(RpcClient& c, const std::string& id, double wait_s) {
  const auto t0 = std::chrono::steady_clock::now();
  Json j;
  while (seconds_since(t0) < wait_s) {
    j = wait_job(c, id, [](const Json& x) {
      const std::string s = x["state"];
      return s == "waiting_sheet" || s == "completed" || s == "failed" || s == "paused" || s == "cancelled";
    }, wait_s);
    if (j["state"] != "waiting_sheet") return j;
    call_ok(c, "job.confirm_sheet", {{"job", id}, {"sheet", j["current_sheet"]}});
  }
  return j;
}

// The knob on 5 mm sheets, submitted, planned and its first sheet confirmed; returns once the
// CNC has executed `blocks` blocks of it (the job's id; empty after a failure).
std::string cut_sheet_one_of_the_knob(RpcClient& c, const Cell& cell, const Laminad& daemon, int blocks) {
  const Json job = call_ok(c, "job.submit", {{"model", kModel}, {"settings", {{"stock", "5"}}}});
  const std::string id = job["id"];
  const Json planned = wait_state(c, id, "waiting_sheet", 120);
  EXPECT_EQ(planned["state"], "waiting_sheet") << daemon.log();
  if (planned["state"] != "waiting_sheet") return {};
  call_ok(c, "job.confirm_sheet", {{"job", id}, {"sheet", 1}});
  const bool cutting = sim::testing::wait_status(
      cell.sim.control_port(), [blocks](const Json& s) { return s["executed_blocks"] > blocks; }, 60);
  EXPECT_TRUE(cutting) << "the CNC never got to block " << blocks << ": "
                       << sim::testing::control_status(cell.sim.control_port()).dump() << daemon.log();
  return cutting ? id : std::string();
}

TEST(LaminadJobs, SubmittedModelIsPlannedAndEverySheetCutLineForLine) {
  Cell cell({}, 50);
  Laminad daemon(cell.config(), cell.dir.file(""));
  RpcClient c = connect(cell.socket());
  const Json info = call_ok(c, "server.info");
  EXPECT_EQ(info["name"], "laminad");

  Json job = call_ok(c, "job.submit", {{"model", kModel}, {"settings", {{"stock_file", kRemnants}, {"microjoints", 2}}}});
  const std::string id = job["id"];
  EXPECT_EQ(job["state"], "queued");
  job = wait_state(c, id, "waiting_sheet", 120);
  ASSERT_EQ(job["state"], "waiting_sheet") << job.dump(2) << daemon.log();
  ASSERT_GE(job["sheets"].size(), 2u) << "the remnant rack needs several sheets";
  EXPECT_EQ(job["current_sheet"], 1);
  // Nothing moves before the operator confirms the sheet.
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  EXPECT_TRUE(executed(cell.log()).empty());
  // The wrong sheet is refused.
  auto wrong = c.call("job.confirm_sheet", {{"job", id}, {"sheet", 2}});
  ASSERT_FALSE(wrong);
  EXPECT_EQ(wrong.error().code, -32602);
  // Integers are range-checked, not narrowed: 4294967297 is not sheet 1 (issue 16, item 10).
  for (const Json& sheet : {Json(4294967297LL), Json(-1), Json(0), Json(18446744073709551615ULL)}) {
    auto out_of_range = c.call("job.confirm_sheet", {{"job", id}, {"sheet", sheet}});
    ASSERT_FALSE(out_of_range) << sheet;
    EXPECT_EQ(out_of_range.error().code, -32602) << sheet;
    EXPECT_NE(out_of_range.error().message.find("out of range"), std::string::npos) << out_of_range.error().message;
  }
  EXPECT_TRUE(executed(cell.log()).empty()) << "nothing was confirmed";

  job = run_to_completion(c, id, 300);
  ASSERT_EQ(job["state"], "completed") << job.dump(2) << daemon.log();
  std::vector<std::string> expected;
  for (const Json& s : job["sheets"]) {
    EXPECT_EQ(s["state"], "done");
    const auto lines = program_lines(s["program"]);
    EXPECT_EQ(s["lines"], lines.size());
    expected.insert(expected.end(), lines.begin(), lines.end());
  }
  const auto log = executed(cell.log());
  ASSERT_EQ(log.size(), expected.size());
  for (std::size_t i = 0; i < log.size(); ++i) {
    ASSERT_EQ(log[i].line, expected[i]) << "block " << i + 1;
    ASSERT_TRUE(log[i].completed) << "block " << i + 1;
  }
  EXPECT_GT(job["summary"]["layers"].get<int>(), 0);
  EXPECT_TRUE(std::filesystem::exists(job["summary"]["stack"].get<std::string>()));
  // The cell is left safe: jet, abrasive and pump off.
  const Json st = call_ok(c, "machine.status");
  EXPECT_EQ(st["cell"]["jet_is_on"], false);
  const Json sim_status = sim::testing::control_status(cell.sim.control_port());
  EXPECT_EQ(sim_status["starvation"], 0);
  RecordProperty("paced_slowdowns", sim_status["paced_slowdowns"].dump());
}

// Through the client as the operator types it: `lamina hold`, `lamina status`, `lamina resume`.
TEST(LaminadJobs, HoldThenResumeFinishesTheSheet) {
  Cell cell({}, 40);
  Laminad daemon(cell.config(), cell.dir.file(""));
  RpcClient c = connect(cell.socket());
  Json job = call_ok(c, "job.submit", {{"model", kModel}, {"settings", {{"stock", "5"}}}});
  const std::string id = job["id"];
  job = wait_state(c, id, "waiting_sheet", 120);
  ASSERT_EQ(job["state"], "waiting_sheet") << daemon.log();
  call_ok(c, "job.confirm_sheet", {{"job", id}, {"sheet", 1}});
  ASSERT_TRUE(sim::testing::wait_status(cell.sim.control_port(), [](const Json& s) { return s["executed_blocks"] > 100; }, 60));
  const ClientRun hold = run_client(cell.socket(), "hold");
  ASSERT_EQ(hold.exit_code, 0) << hold.output;
  job = call_ok(c, "job.get", {{"job", id}});
  EXPECT_EQ(job["state"], "paused");
  ASSERT_TRUE(sim::testing::wait_status(cell.sim.control_port(), [](const Json& s) { return s["state"] == "hold"; }, 10));
  const auto held_at = executed(cell.log()).size();
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  EXPECT_EQ(executed(cell.log()).size(), held_at) << "nothing runs while held";
  const ClientRun status = run_client(cell.socket(), "status");
  EXPECT_EQ(status.exit_code, 0);
  EXPECT_EQ(status.output.rfind("hold  X", 0), 0u) << "state, then the position: " << status.output;
  EXPECT_NE(status.output.find("job " + id), std::string::npos) << status.output;
  const ClientRun resume = run_client(cell.socket(), "resume");  // no job: the held machine goes on
  ASSERT_EQ(resume.exit_code, 0) << resume.output;
  job = run_to_completion(c, id, 300);
  ASSERT_EQ(job["state"], "completed") << job.dump(2);
  const auto lines = program_lines(job["sheets"][0]["program"]);
  const auto log = executed(cell.log());
  ASSERT_EQ(log.size(), lines.size());
  for (std::size_t i = 0; i < log.size(); ++i) ASSERT_EQ(log[i].line, lines[i]);
}

// The first contour after line `after` with at least `cuts` cutting moves (modal: lines of
// coordinates after the G1): its comment's index.
std::size_t long_contour(const std::vector<std::string>& lines, std::size_t after, int cuts) {
  std::size_t start = 0;
  int moves = 0;
  for (std::size_t i = after; i < lines.size(); ++i) {
    if (lines[i].find("(CONTOUR") == 0) {
      if (start && moves >= cuts) return start;
      start = i;
      moves = 0;
    } else if (lines[i][0] == 'X' || lines[i][0] == 'Y' || lines[i].find("G1") != std::string::npos) {
      ++moves;
    }
  }
  return 0;
}

// The CNC stops taking lines mid-contour (its serial input hangs 3 s: lamina-sim `stall`) and
// runs dry with the water on. The daemon stops it at once with the jet off (before: after the
// stall rule's 2 s, the water on all along) and pauses the job with the reason; the operator's
// resume cuts that contour again from its start, and every other contour once. A small queue
// (16 planner blocks, 256 bytes) at real time, so it runs dry well inside the contour.
TEST(LaminadJobs, AControllerThatStallsWithTheJetOnIsStoppedAtOnceAndResumed) {
  Cell cell({"--planner-blocks", "16", "--rx-buffer", "256"}, 10);
  Laminad daemon(cell.config(), cell.dir.file(""));
  RpcClient c = connect(cell.socket());
  const std::string id = cut_sheet_one_of_the_knob(c, cell, daemon, 10);
  ASSERT_FALSE(id.empty());
  const auto lines = program_lines(call_ok(c, "job.get", {{"job", id}})["sheets"][0]["program"]);
  // Well inside the contour's cut, past its lead-in (which turns the head in pieces of 2°: up to 30 lines).
  const std::size_t contour = long_contour(lines, 300, 100);
  ASSERT_GT(contour, 0u) << "no contour of 100 cuts in the knob's first sheet";
  const int port = cell.sim.control_port();
  const auto executed_past = [&](std::size_t n) {
    return sim::testing::wait_status(port, [n](const Json& s) { return s["executed_blocks"].get<std::size_t>() > n; }, 60);
  };
  ASSERT_TRUE(executed_past(contour - 40));
  EXPECT_EQ(sim::testing::control(port, "time-scale 1").substr(0, 2), "ok");
  ASSERT_TRUE(executed_past(contour + 50));
  EXPECT_EQ(sim::testing::control(port, "stall 3000").substr(0, 2), "ok");
  const Json paused = wait_job(c, id, [](const Json& j) { return j["state"] != "cutting"; }, 30);
  ASSERT_EQ(paused["state"], "paused") << paused.dump(2) << daemon.log();
  EXPECT_NE(paused["error"].get<std::string>().find("stood Idle with the jet on"), std::string::npos) << paused["error"];
  lamina::drivers::testing::PlcProbe plc(cell.sim.modbus_port());
  EXPECT_EQ(plc.input(lamina::drivers::testing::map::kInputJetIsOn), 0) << "the jet is off while it stands";
  ASSERT_TRUE(wait_for_log_event(cell, "stall_end", 10));
  EXPECT_TRUE(executed(cell.log()).size() < lines.size()) << "it never resumes by itself";
  call_ok(c, "job.resume", {{"job", id}});
  EXPECT_EQ(sim::testing::control(port, "time-scale 40").substr(0, 2), "ok");
  const Json job = run_to_completion(c, id, 300);
  ASSERT_EQ(job["state"], "completed") << job.dump(2);
  const auto machine = campaign::parse_machine_log(sim::testing::read_log(cell.log()));
  const auto contours = campaign::check_contours_cut_once(lines, machine, true);
  EXPECT_TRUE(contours.violations.empty()) << contours.violations.size() << " violation(s), first: "
                                           << (contours.violations.empty() ? "" : contours.violations[0]);
  EXPECT_EQ(contours.cut_again, 1u);
}

TEST(LaminadJobs, AbortStopsSafelyAndJobResumeRestartsAtTheContour) {
  Cell cell({}, 40);
  Laminad daemon(cell.config(), cell.dir.file(""));
  RpcClient c = connect(cell.socket());
  const std::string id = cut_sheet_one_of_the_knob(c, cell, daemon, 300);
  if (id.empty()) return;
  call_ok(c, "machine.abort");
  Json job = wait_state(c, id, "paused", 30);
  ASSERT_EQ(job["state"], "paused") << job.dump(2);
  EXPECT_FALSE(job["error"].get<std::string>().empty());
  // Stopped means stopped: nothing runs and the jet is off until the operator says so.
  const auto stopped_at = executed(cell.log()).size();
  std::this_thread::sleep_for(std::chrono::milliseconds(700));
  EXPECT_EQ(executed(cell.log()).size(), stopped_at);
  EXPECT_EQ(call_ok(c, "machine.status")["cell"]["jet_is_on"], false);

  call_ok(c, "job.resume", {{"job", id}});
  job = run_to_completion(c, id, 300);
  ASSERT_EQ(job["state"], "completed") << job.dump(2) << daemon.log();
  // Every line ran; the resumed part starts at a contour marker inside the stopped contour.
  const auto lines = program_lines(job["sheets"][0]["program"]);
  const auto log = executed(cell.log());
  std::size_t first_run_done = 0;
  while (first_run_done < log.size() && first_run_done < lines.size() && log[first_run_done].line == lines[first_run_done] &&
         log[first_run_done].completed)
    ++first_run_done;
  std::size_t restart = lines.size();
  for (std::size_t i = first_run_done; i < log.size(); ++i)
    if (log[i].line.rfind("(CONTOUR ", 0) == 0) {
      for (std::size_t k = 0; k < lines.size(); ++k)
        if (lines[k] == log[i].line) restart = k;
      break;
    }
  ASSERT_LT(restart, lines.size()) << "no contour marker after the stop";
  // The resume point from the post's map of the program (report.json): the first contour whose
  // last cutting line had not run restarts at its marker. A contour whose cutting had all run
  // is not cut again, even when the stop came before its retract (those lines need not run:
  // the resume's own preamble goes to safe Z first); no cutting line is skipped.
  std::ifstream report_file(std::filesystem::path(job["artefacts"].get<std::string>()) / "report.json");
  const Json report = Json::parse(report_file);
  std::size_t unfinished = lines.size();
  for (const auto& contour : report["sheets"][0]["contour_lines"])
    if (contour["last_cut_line"].get<std::size_t>() > first_run_done) {
      unfinished = contour["line"].get<std::size_t>() - 1;
      break;
    }
  EXPECT_EQ(restart, unfinished) << "restart at the start of the contour being cut (first run: " << first_run_done
                                 << " lines done)";
  EXPECT_EQ(log.back().line, lines.back());
}

// A fault stops the cut and leaves the pump pressurised for a resume; the operator cancels
// instead: nobody will resume, so pump and abrasive go off (issue 16, item 3: a cutter thread
// that had ended on the fault was still joinable, and the cancel skipped the cell's shutdown).
TEST(LaminadJobs, CancelAfterAFaultTurnsPumpAndAbrasiveOff) {
  Cell cell({}, 40);
  Laminad daemon(cell.config(), cell.dir.file(""));
  RpcClient c = connect(cell.socket());
  const std::string id = cut_sheet_one_of_the_knob(c, cell, daemon, 100);
  if (id.empty()) return;
  ASSERT_EQ(sim::testing::control(cell.sim.control_port(), "pressure drop"), "ok");
  const Json job = wait_state(c, id, "paused", 30);
  ASSERT_EQ(job["state"], "paused") << job.dump(2);
  drivers::testing::PlcProbe plc(cell.sim.modbus_port());
  ASSERT_EQ(plc.coil(drivers::testing::map::kCoilPump), 1) << "the stop keeps the pump for a resume";
  call_ok(c, "job.cancel", {{"job", id}});
  EXPECT_EQ(wait_state(c, id, "cancelled", 10)["state"], "cancelled");
  const auto t0 = std::chrono::steady_clock::now();
  while ((plc.coil(drivers::testing::map::kCoilPump) != 0 || plc.coil(drivers::testing::map::kCoilAbrasive) != 0) &&
         seconds_since(t0) < 10)
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  EXPECT_EQ(plc.coil(drivers::testing::map::kCoilPump), 0) << daemon.log();
  EXPECT_EQ(plc.coil(drivers::testing::map::kCoilAbrasive), 0);
  EXPECT_EQ(plc.coil(drivers::testing::map::kCoilJet), 0);
}

TEST(LaminadJobs, CancelWhilePlanningStopsThePlanner) {
  Cell cell;
  Laminad daemon(cell.config(), cell.dir.file(""));
  RpcClient c = connect(cell.socket());
  // Fine sub-slices and sections: a plan that takes a while.
  Json job = call_ok(c, "job.submit", {{"model", kModel}, {"settings", {{"sub_slice_mm", 0.02}, {"tolerance_mm", 0.01}}}});
  const std::string id = job["id"];
  ASSERT_EQ(wait_state(c, id, "planning", 30)["state"], "planning");
  const auto t0 = std::chrono::steady_clock::now();
  call_ok(c, "job.cancel", {{"job", id}});
  job = wait_state(c, id, "cancelled", 10);
  EXPECT_EQ(job["state"], "cancelled") << job.dump(2);
  EXPECT_LT(seconds_since(t0), 5.0);
  // ([l]: the pattern must not match pgrep's own shell)
  EXPECT_EQ(std::system("pgrep -f '[l]amina plan .*knob.stl.*sub-slice 0.02' > /dev/null"), 256) << "the planner is gone";
  // The daemon takes the next job as usual.
  Json next = call_ok(c, "job.submit", {{"model", kModel}, {"settings", {{"stock", "5"}}}});
  EXPECT_EQ(wait_state(c, next["id"], "waiting_sheet", 120)["state"], "waiting_sheet");
}

}  // namespace
}  // namespace lamina::daemon::testing
