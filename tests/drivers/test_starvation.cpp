// A machine the host cannot keep fed (issue 16, fault campaign round 2): it runs out of program
// mid-contour and stands Idle with the jet on, drilling the part. Two causes, two tests:
//  - the host's own slow work on the streaming thread (a progress record written with a full
//    sync to a busy disk took seconds) — the stream must not wait for it;
//  - a line too slow for the program (short segments at a high feed), or any other stall the
//    host cannot prevent — the machine is held and the jet goes off, for the operator to resume.
#include <atomic>
#include <cstdio>
#include <mutex>
#include <thread>

#include <boost/asio/steady_timer.hpp>
#include <gtest/gtest.h>

#include "campaign_checks.hpp"
#include "modbus_test_client.hpp"
#include "sim_cut.hpp"

namespace lamina::drivers::testing {
namespace {

campaign::JetCheck jet_at_standstill(const SimCut& cut, double limit_wall_s) {
  const auto log = campaign::parse_machine_log(sim::testing::read_log(cut.dir.file("exec.jsonl")));
  return campaign::check_jet_off_at_standstill(log, limit_wall_s, 1.1);
}

std::string joined(const std::vector<std::string>& lines) {
  std::string out;
  for (const auto& l : lines) out += l + "\n";
  return out;
}

// Straight cuts in the XY plane, `moves` segments of `step_mm` each at `feed_mm_per_min`.
std::vector<std::string> straight_program(int contours, int moves, double step_mm, double feed_mm_per_min) {
  std::vector<std::string> p{"(TEST PROGRAM)", "G21G90G94G17", "G0X0Y0Z10A0C0"};
  for (int k = 0; k < contours; ++k) {
    const double y = 20 + 20 * k;
    p.push_back(fmt::format("(CONTOUR {} L{}-1 OUTLINE 0 PASS 0 FREES)", k, k + 1));
    p.push_back(fmt::format("G0X10Y{:.3f}Z10", y));
    p.push_back("Z0");
    p.push_back("M3");
    p.push_back("G4P0.05");
    for (int i = 1; i <= moves; ++i) p.push_back(fmt::format("G1X{:.3f}Y{:.3f}F{:.0f}", 10 + step_mm * i, y, feed_mm_per_min));
    p.push_back("M5");
    p.push_back("G0Z10");
  }
  p.push_back("M30");
  return p;
}

// 2 contours of 300 moves of 0.5 mm at 30 mm/s: 5 s each. The simulator's queue (100 planner
// blocks and 1 KiB of receive buffer) holds about 2.5 s of it; a 3 s wait starves it.
TEST(Starvation, ASlowProgressRecordDoesNotHoldUpTheStream) {
  SimCut cut({}, {.program = straight_program(2, 300, 0.5, 1800)});
  std::atomic<bool> slept{false};
  cut.job->on_progress([&](const CutReport& r) {
    if (r.lines_accepted >= 120 && !slept.exchange(true)) std::this_thread::sleep_for(std::chrono::seconds(3));
  });
  cut.start();
  const CutReport r = cut.finish();
  ASSERT_EQ(r.state, CutState::completed) << (r.reason ? r.reason->message : "");
  EXPECT_TRUE(slept) << "the slow record was never asked for";
  EXPECT_EQ(executed_lines(cut.dir.file("exec.jsonl")), cut.program);
  const auto jet = jet_at_standstill(cut, 0.1);
  EXPECT_EQ(jet.standstills_with_jet, 0u) << "the machine stood with the jet on, worst " << jet.worst_wall_s
                                           << " s:\n" << joined(jet.violations);
}

// The controller stops taking lines for 4 s (lamina-sim `stall`: its serial task hangs, lines
// wait unread in its receive buffer), longer than its queue of motion: it runs dry mid-contour
// and stands Idle with the water on. Before: the water flowed ~2 s, until the link's stall
// rule stopped the job. Now the hold watch sees it in the PLC's view (Idle, the jet M-code on,
// the block it stands at not a dwell, and one the controller has): a stall, stopped at once
// with the jet off; the operator's resume cuts the contour again from its start.
TEST(Starvation, AControllerThatStallsWithTheJetOnIsStoppedAtOnce) {
  SimCut cut({}, {.program = straight_program(2, 300, 0.5, 1800)});
  cut.start();
  ASSERT_TRUE(cut.cutting_with_the_jet_on());
  EXPECT_EQ(sim::testing::control(cut.sim.control_port(), "stall 4000").substr(0, 2), "ok");
  CutReport r = cut.finish();
  ASSERT_EQ(r.state, CutState::stopped) << (r.reason ? r.reason->message : "");
  ASSERT_TRUE(r.reason);
  EXPECT_EQ(r.reason->code, LinkErrorCode::timeout);
  EXPECT_NE(r.reason->message.find("stood Idle with the jet on"), std::string::npos) << r.reason->message;
  ASSERT_TRUE(wait_for([&] { return !cut.events("stall_end").empty(); }, 10));
  r = cut.job->resume();
  ASSERT_EQ(r.state, CutState::completed) << (r.reason ? r.reason->message : "");
  const auto log = campaign::parse_machine_log(sim::testing::read_log(cut.dir.file("exec.jsonl")));
  const auto contours = campaign::check_contours_cut_once(cut.program, log, true);
  EXPECT_TRUE(contours.violations.empty()) << joined(contours.violations);
  EXPECT_EQ(contours.cut_again, 1u);
  const auto jet = jet_at_standstill(cut, 0.25);  // as the campaign's ctest run on a loaded machine
  std::printf("stall: water on the standing machine %zu time(s), the longest %.0f ms (wall)\n",
              jet.standstills_with_jet, jet.worst_wall_s * 1000);
  EXPECT_TRUE(jet.violations.empty()) << joined(jet.violations);
  EXPECT_GE(jet.standstills_with_jet, 1u) << "the machine never stood with the water on: the test tests nothing";
}

// A serial adapter whose writes hang once, for `hang_ms`, after `after_bytes` went out (a USB
// hiccup; a host thread that cannot run): the host falls behind, the link itself sound.
class HangingWrites : public Transport {
 public:
  HangingWrites(boost::asio::io_context& io, std::unique_ptr<Transport> inner, std::size_t after_bytes, int hang_ms)
      : timer_(io), inner_(std::move(inner)), after_bytes_(after_bytes), hang_ms_(hang_ms) {}
  void async_read_some(std::span<std::uint8_t> buffer, ReadHandler handler) override {
    inner_->async_read_some(buffer, std::move(handler));
  }
  void async_write(std::span<const std::uint8_t> data, WriteHandler handler) override {
    if (hung_ || written_ < after_bytes_) return write_now(data, std::move(handler));
    hung_ = true;
    timer_.expires_after(std::chrono::milliseconds(hang_ms_));
    timer_.async_wait([this, data, handler = std::move(handler)](const boost::system::error_code& ec) mutable {
      if (ec) return handler(std::make_error_code(std::errc::operation_canceled), 0);
      write_now(data, std::move(handler));
    });
  }
  void close() override {
    timer_.cancel();
    inner_->close();
  }
  std::string describe() const override { return inner_->describe(); }

 private:
  void write_now(std::span<const std::uint8_t> data, WriteHandler handler) {
    inner_->async_write(data, [this, handler = std::move(handler)](std::error_code ec, std::size_t n) {
      written_ += n;
      handler(ec, n);
    });
  }
  boost::asio::steady_timer timer_;
  std::unique_ptr<Transport> inner_;
  std::size_t after_bytes_, written_ = 0;
  int hang_ms_;
  bool hung_ = false;
};

// The host's writes hang 3 s a few hundred lines into the first contour; the machine's queue
// holds about 2.5 s: it runs dry at a line the host has not sent. The link is sound, so it is a
// hold: feed hold (the PLC's button: the line's is stuck behind the hang too), jet off, the
// owner told; the operator's resume opens the jet in the kerf, and every line runs once.
TEST(Starvation, AMachineTheHostFallsBehindOnIsHeldWithTheJetOff) {
  SimCut cut({.jet_restart_s = 0.3},
             {.program = straight_program(2, 300, 0.5, 1800), .make_link = [](const std::string& path) {
                StreamerSettings settings;
                settings.pace_bytes_per_s = 11520;
                return std::make_unique<Streamer>(
                    [path](boost::asio::io_context& io) -> std::expected<std::unique_ptr<Transport>, LinkError> {
                      auto port = open_serial(io, path, SerialSettings{});
                      if (!port) return std::unexpected(port.error());
                      return std::make_unique<HangingWrites>(io, std::move(*port), 4000, 3000);
                    },
                    make_grbl_protocol(), settings);
              }});
  std::vector<LinkError> holds;
  std::mutex holds_mutex;
  cut.job->on_hold([&](const LinkError& why) {
    std::lock_guard lock(holds_mutex);
    holds.push_back(why);
  });
  cut.start();
  PlcProbe plc(cut.sim.modbus_port());
  ASSERT_TRUE(wait_for([&] {
    std::lock_guard lock(holds_mutex);
    return !holds.empty();
  }, 30)) << "the machine ran dry and the job did not hold it";
  {
    std::lock_guard lock(holds_mutex);
    EXPECT_EQ(holds[0].code, LinkErrorCode::starved) << holds[0].message;
  }
  ASSERT_TRUE(wait_for([&] {
    return sim::testing::control_status(cut.sim.control_port())["state"] == "hold" && plc.input(map::kInputJetIsOn) == 0;
  }, 10)) << "not held with the jet off";
  std::this_thread::sleep_for(std::chrono::milliseconds(3500));  // the hang is over; nothing may move by itself
  EXPECT_EQ(sim::testing::control_status(cut.sim.control_port())["state"], "hold") << "it never resumes by itself";
  cut.job->continue_motion();
  const CutReport r = cut.finish();
  ASSERT_EQ(r.state, CutState::completed) << (r.reason ? r.reason->message : "");
  EXPECT_EQ(executed_lines(cut.dir.file("exec.jsonl")), cut.program) << "every line once, in order";
  const auto jet = jet_at_standstill(cut, 0.25);
  std::printf("host behind: water on the standing machine %zu time(s), the longest %.0f ms (wall)\n",
              jet.standstills_with_jet, jet.worst_wall_s * 1000);
  EXPECT_TRUE(jet.violations.empty()) << joined(jet.violations);
  EXPECT_GE(jet.standstills_with_jet, 1u) << "the machine never stood with the water on: the test tests nothing";
  EXPECT_EQ(jet.restarts_in_kerf, 1u) << "the resume opens the jet in the kerf once";
}

}  // namespace
}  // namespace lamina::drivers::testing
