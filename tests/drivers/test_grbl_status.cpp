// parse_grbl_status against reports as grblHAL and Grbl 1.1 send them (Grbl wiki
// "Real-time Status Reports", grblHAL report.c).
#include <gtest/gtest.h>

#include "lamina/drivers/controller_status.hpp"

namespace lamina::drivers {
namespace {

TEST(GrblStatus, FullGrblHalReportWithFiveAxes) {
  const auto s = parse_grbl_status(
      "<Run|MPos:10.000,20.500,-1.250,0.000,90.000|Bf:34,1009|Ln:120|FS:1500,0|Pn:XY|"
      "WCO:0.000,0.000,0.000,0.000,0.000|Ov:100,100,100|A:S>");
  ASSERT_TRUE(s);
  EXPECT_EQ(s->state, ControllerState::run);
  EXPECT_EQ(s->state_text, "Run");
  ASSERT_TRUE(s->machine_position);
  EXPECT_DOUBLE_EQ((*s->machine_position)[0], 10.0);
  EXPECT_DOUBLE_EQ((*s->machine_position)[1], 20.5);
  EXPECT_DOUBLE_EQ((*s->machine_position)[2], -1.25);
  EXPECT_DOUBLE_EQ((*s->machine_position)[4], 90.0);
  EXPECT_EQ(s->planner_blocks_free, 34);
  EXPECT_EQ(s->rx_bytes_free, 1009);
  EXPECT_EQ(s->line_number, 120);
  ASSERT_TRUE(s->feed_mm_per_s);
  EXPECT_DOUBLE_EQ(*s->feed_mm_per_s, 25.0);  // 1500 mm/min
}

TEST(GrblStatus, ReportWithoutOptionalFields) {
  const auto s = parse_grbl_status("<Idle|MPos:0.000,0.000,0.000,0.000,0.000|Bf:100,1024>");
  ASSERT_TRUE(s);
  EXPECT_EQ(s->state, ControllerState::idle);
  EXPECT_TRUE(s->machine_position);
  EXPECT_FALSE(s->line_number);
  EXPECT_FALSE(s->feed_mm_per_s);
  // A bare state is a report too (Grbl with every report option off).
  const auto bare = parse_grbl_status("<Idle>");
  ASSERT_TRUE(bare);
  EXPECT_FALSE(bare->machine_position);
  EXPECT_FALSE(bare->planner_blocks_free);
}

TEST(GrblStatus, HoldCompleteVersusInProgress) {
  EXPECT_EQ(parse_grbl_status("<Hold:0|MPos:1,2,3,4,5|FS:0,0>")->state, ControllerState::hold);
  EXPECT_EQ(parse_grbl_status("<Hold:1|MPos:1,2,3,4,5|FS:120,0>")->state, ControllerState::hold_pending);
  EXPECT_EQ(parse_grbl_status("<Hold:1|MPos:1,2,3,4,5>")->state_text, "Hold:1");
}

TEST(GrblStatus, EveryState) {
  const std::pair<const char*, ControllerState> cases[] = {
      {"<Idle>", ControllerState::idle},   {"<Run>", ControllerState::run},
      {"<Alarm>", ControllerState::alarm}, {"<Door:1>", ControllerState::door},
      {"<Door:0>", ControllerState::door}, {"<Check>", ControllerState::check},
      {"<Home>", ControllerState::home},   {"<Sleep>", ControllerState::sleep},
      {"<Jog>", ControllerState::jog},     {"<Tool>", ControllerState::tool},
      {"<Hold:0>", ControllerState::hold}, {"<Hold:1>", ControllerState::hold_pending},
      {"<Dance>", ControllerState::unknown}};
  for (const auto& [report, state] : cases) {
    const auto s = parse_grbl_status(report);
    ASSERT_TRUE(s) << report;
    EXPECT_EQ(s->state, state) << report;
  }
  EXPECT_STREQ(to_string(ControllerState::hold_pending), "hold_pending");
  EXPECT_STREQ(to_string(ControllerState::tool), "tool");
  EXPECT_STREQ(to_string(ControllerState::idle), "idle");
}

TEST(GrblStatus, OnlyFiveAxesMapOntoTheMachine) {
  // Classic Grbl reports XYZ: the state is good, the position cannot be ours.
  const auto three = parse_grbl_status("<Idle|MPos:1.000,2.000,3.000|FS:0,0>");
  ASSERT_TRUE(three);
  EXPECT_EQ(three->state, ControllerState::idle);
  EXPECT_FALSE(three->machine_position);
  const auto six = parse_grbl_status("<Idle|MPos:1,2,3,4,5,6>");
  ASSERT_TRUE(six);
  EXPECT_FALSE(six->machine_position);
}

TEST(GrblStatus, WorkPositionWhenNoMachinePosition) {
  const auto with_offset = parse_grbl_status("<Idle|WPos:1,2,3,4,5|WCO:10,20,30,0,0>");
  ASSERT_TRUE(with_offset && with_offset->machine_position);
  EXPECT_DOUBLE_EQ((*with_offset->machine_position)[0], 11.0);
  EXPECT_DOUBLE_EQ((*with_offset->machine_position)[2], 33.0);
  const auto alone = parse_grbl_status("<Idle|WPos:1,2,3,4,5>");
  ASSERT_TRUE(alone && alone->machine_position);
  EXPECT_DOUBLE_EQ((*alone->machine_position)[1], 2.0);
}

TEST(GrblStatus, FeedAloneAndUnknownFieldsIgnored) {
  const auto s = parse_grbl_status("<Run|MPos:0,0,0,0,0|F:600|SD:12.5,/prog.nc|H:0,1|T:3|MPG:0|NEWFLAG>");
  ASSERT_TRUE(s);
  ASSERT_TRUE(s->feed_mm_per_s);
  EXPECT_DOUBLE_EQ(*s->feed_mm_per_s, 10.0);
}

TEST(GrblStatus, WithoutChevrons) {
  const auto s = parse_grbl_status("Idle|MPos:0,0,0,0,0|Bf:15,128");
  ASSERT_TRUE(s);
  EXPECT_EQ(s->rx_bytes_free, 128);
}

TEST(GrblStatus, MalformedIsRejected) {
  for (const char* bad : {"", "<>", "<Idle|MPos:1,2,3,4,5", "Idle|MPos:1,2>", "<Idle|MPos:1,x,3,4,5>",
                          "<Idle|MPos:1,2>", "<Idle|Bf:12>", "<Idle|Bf:a,b>", "<Run|Ln:12a>", "<Run|FS:fast,0>",
                          "<Run|MPos:1,,3,4,5>"})
    EXPECT_FALSE(parse_grbl_status(bad)) << bad;
}

}  // namespace
}  // namespace lamina::drivers
