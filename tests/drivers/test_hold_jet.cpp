// A feed hold and the jet (issue 16, item 1), against lamina-sim with its PLC: the operator's
// hold (and the PLC's hold button) during a cut. Before: the PLC's jet output stayed on for the
// whole hold, a standing abrasive jet drilling the part and the bed.
#include <thread>

#include <gtest/gtest.h>
#include <modbus/modbus.h>

#include "lamina/drivers/cut_job.hpp"
#include "lamina/drivers/streamer.hpp"
#include "link_test_support.hpp"
#include "sim_cut.hpp"
#include "modbus_test_client.hpp"

namespace lamina::drivers::testing {
namespace {


constexpr int kInAbrasiveFlow = 1;      // g/min (docs/modbus-map.md)
constexpr int kCoilCncFeedHold = 4;     // the PLC's panel buttons
constexpr int kCoilCncCycleStart = 5;

void press(int modbus_port, int coil) {
  modbus_t* ctx = modbus_new_tcp("127.0.0.1", modbus_port);
  ASSERT_EQ(modbus_connect(ctx), 0);
  EXPECT_EQ(modbus_write_bit(ctx, coil, 1), 1);
  modbus_close(ctx);
  modbus_free(ctx);
}

TEST(FeedHold, TheJetGoesOffOnceTheMachineStandsAndResumeOpensItBeforeTheMotion) {
  SimCut cut({.jet_restart_s = 0.5});
  cut.start();
  ASSERT_TRUE(cut.cutting_with_the_jet_on());
  cut.job->hold();
  PlcProbe plc(cut.sim.modbus_port());
  ASSERT_TRUE(wait_for([&] { return plc.input(map::kInputJetIsOn) == 0 && plc.in_reg(kInAbrasiveFlow) == 0; }, 10))
      << "the jet and the abrasive stay on during the hold";
  EXPECT_EQ(sim::testing::control_status(cut.sim.control_port())["state"], "hold");
  EXPECT_EQ(plc.coil(map::kCoilPump), 1) << "the pump stays pressurised for the resume";
  cut.job->continue_motion();
  const CutReport r = cut.finish();
  ASSERT_EQ(r.state, CutState::completed) << (r.reason ? r.reason->message : "");
  EXPECT_EQ(executed_lines(cut.dir.file("exec.jsonl")), cut.program) << "every line once, in order";

  // From the simulator's log: the jet went off while the machine stood in the hold, came on
  // again in the hold, and the motion went on only after the restart time.
  const auto jets = cut.events("jet");
  const auto held = std::find_if(jets.begin(), jets.end(), [](const nlohmann::json& e) {
    return e["flowing"] == false && e["state"] == "hold";
  });
  ASSERT_NE(held, jets.end()) << "no jet-off in the hold";
  ASSERT_NE(std::next(held), jets.end());
  const nlohmann::json& back_on = *std::next(held);
  EXPECT_EQ(back_on["flowing"], true);
  EXPECT_EQ(back_on["state"], "hold") << "the jet opens in the kerf before the motion";
  const auto states = cut.events("state");
  const auto moving_again = std::find_if(states.begin(), states.end(), [&](const nlohmann::json& e) {
    return e["state"] == "run" && e["t"].get<double>() > back_on["t"].get<double>();
  });
  ASSERT_NE(moving_again, states.end());
  // The simulator stamps each event with its loop iteration's clock, read before that iteration
  // reads the line's bytes and ticks the PLC: a cycle start can be stamped a little before it
  // arrived (0.23 ms short was seen, 2026-12-05) — its stamps are good to an iteration, not to a
  // microsecond. A restart time the host did not keep is off by hundreds of ms, not by 10.
  EXPECT_GE((*moving_again)["t"].get<double>() - back_on["t"].get<double>(), 0.5 - 0.01) << "the jet's restart time";
  const auto hold_complete = std::find_if(states.begin(), states.end(), [](const nlohmann::json& e) {
    return e["state"] == "hold";
  });
  ASSERT_NE(hold_complete, states.end());
  std::printf("jet off %.0f ms after the machine stood in the hold\n",
              1000 * ((*held)["t"].get<double>() - (*hold_complete)["t"].get<double>()));
}

TEST(FeedHold, LongerThanTheLimitBecomesAStopAndTheResumeRunsEveryContourOnce) {
  SimCut cut({.hold_limit_s = 1.0, .jet_restart_s = 0.2});
  cut.start();
  ASSERT_TRUE(cut.cutting_with_the_jet_on());
  cut.job->hold();
  CutReport r = cut.finish();
  ASSERT_EQ(r.state, CutState::stopped);
  EXPECT_EQ(r.reason->code, LinkErrorCode::held_too_long) << r.reason->message;
  ASSERT_TRUE(r.resume);
  PlcProbe plc(cut.sim.modbus_port());
  EXPECT_EQ(plc.input(map::kInputJetIsOn), 0);
  const std::size_t restart = r.resume->restart_index;
  r = cut.job->resume();
  ASSERT_EQ(r.state, CutState::completed) << (r.reason ? r.reason->message : "");
  const auto done = executed_lines(cut.dir.file("exec.jsonl"), false);
  const std::size_t tail = cut.program.size() - restart;
  ASSERT_GE(done.size(), tail);
  for (std::size_t i = 0; i < tail; ++i) EXPECT_EQ(done[done.size() - tail + i], cut.program[restart + i]);
}

// The PLC's hold button (not Lamina's) holds the machine: the same rule turns the jet off. The
// machine's own cycle start then would move it with the jet off: the job stops instead, and
// only Lamina's resume (which opens the jet first) goes on.
TEST(FeedHold, ThePanelsHoldTurnsTheJetOffAndItsCycleStartStopsTheJob) {
  SimCut cut({.jet_restart_s = 0.2});
  cut.start();
  ASSERT_TRUE(cut.cutting_with_the_jet_on());
  press(cut.sim.modbus_port(), kCoilCncFeedHold);
  PlcProbe plc(cut.sim.modbus_port());
  ASSERT_TRUE(wait_for([&] { return plc.input(map::kInputJetIsOn) == 0; }, 10));
  press(cut.sim.modbus_port(), kCoilCncCycleStart);
  CutReport r = cut.finish();
  ASSERT_EQ(r.state, CutState::stopped);
  EXPECT_EQ(r.reason->code, LinkErrorCode::left_hold_without_jet) << r.reason->message;
  EXPECT_EQ(plc.input(map::kInputJetIsOn), 0);
  r = cut.job->resume();
  EXPECT_EQ(r.state, CutState::completed) << (r.reason ? r.reason->message : "");
}

// Without a PLC nothing turns the jet off and keeps the position: a standing hold is a stop,
// whose soft reset turns the controller's jet M-code off.
TEST(FeedHold, WithoutAPlcAStandingHoldIsAStopWithTheJetOff) {
  SimCut cut({}, {.with_plc = false});
  cut.start();
  ASSERT_TRUE(cut.cutting_with_the_jet_on());
  cut.job->hold();
  const CutReport r = cut.finish();
  ASSERT_EQ(r.state, CutState::stopped);
  EXPECT_EQ(r.reason->code, LinkErrorCode::held_too_long) << r.reason->message;
  EXPECT_EQ(sim::testing::control_status(cut.sim.control_port())["jet_commanded"], false);
  ASSERT_TRUE(r.resume);
}

}  // namespace
}  // namespace lamina::drivers::testing
