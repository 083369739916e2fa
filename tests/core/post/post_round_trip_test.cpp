// Round trips: hand-built toolpaths → post (every dialect, RTCP and not) → the test's own G-code
// reader → the test's own forward kinematics → the planned tip and tool axis at every move end.
#include "post_round_trip.hpp"
#include "post_toolpaths.hpp"

#include "lamina/core/post.hpp"

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

namespace {

using namespace post_test;

std::vector<post_test::ContourSpec> typical_sheet() {
  using post_test::ContourSpec;
  std::vector<ContourSpec> specs;
  specs.push_back(post_test::cone({100, 100}, 40, 30 * deg, 2.5, 360));               // C crosses ±180° thrice
  specs.push_back(post_test::vertical_rectangle({200, 40}, 60, 30, 10));              // A = 0
  ContourSpec sink = post_test::cone({300, 100}, 12, -45 * deg, 1.0, 180, 0.7);        // countersink, inward
  sink.is_hole = true;
  specs.push_back(sink);
  specs.push_back(post_test::random_walk(1, 150, 55 * deg));                            // arbitrary turns
  return specs;
}

struct RoundTripCase {
  PostDialect dialect;
  bool rtcp;
};

class PostRoundTrip : public ::testing::TestWithParam<RoundTripCase> {};

TEST_P(PostRoundTrip, EveryMoveEndIsThePlannedTipAndAxis) {
  const RoundTripCase c = GetParam();
  HeadKinematics head;
  head.rtcp = c.rtcp;
  PostParams params;
  params.dialect = c.dialect;
  params.title = "Job 12 sheet 3 (6 mm AlMg3)";
  const SheetToolpath tp = post_test::make_toolpath(typical_sheet());
  const RoundTrip rt = round_trip(tp, head, params);
  ASSERT_FALSE(rt.read.motions.empty());
  if (!c.rtcp) {
    EXPECT_GT(rt.g93_lines, 500u);
  }  // the cones and the walk turn the head on every move

  // The 2.5-turn cone unwinds: its C covers 900°.
  double c_lo = 1e9, c_hi = -1e9;
  const auto& cone = tp.contours[0];
  for (std::size_t i = cone.first_move; i < cone.end_move; ++i) {
    c_lo = std::min(c_lo, rt.posted.poses[i].c_rad / deg);
    c_hi = std::max(c_hi, rt.posted.poses[i].c_rad / deg);
  }
  EXPECT_NEAR(c_hi - c_lo, 900.0, 1.0);

  const double bytes_per_move =
      static_cast<double>(rt.posted.five_axis_bytes) / static_cast<double>(std::max<std::size_t>(1, rt.posted.five_axis_moves));
  std::printf("%s rtcp=%d: %zu lines, %zu bytes, five_axis_moves %zu, five_axis_bytes %zu (%.1f bytes/move)\n",
              lamina::post_dialect_name(c.dialect), c.rtcp ? 1 : 0, rt.posted.lines, rt.posted.text.size(),
              rt.posted.five_axis_moves, rt.posted.five_axis_bytes, bytes_per_move);
  RecordProperty("five_axis_moves", static_cast<int>(rt.posted.five_axis_moves));
  RecordProperty("five_axis_bytes", static_cast<int>(rt.posted.five_axis_bytes));
}

INSTANTIATE_TEST_SUITE_P(Dialects, PostRoundTrip,
                         ::testing::Values(RoundTripCase{PostDialect::grblhal, false}, RoundTripCase{PostDialect::fanuc, false},
                                           RoundTripCase{PostDialect::fanuc, true}, RoundTripCase{PostDialect::linuxcnc, false},
                                           RoundTripCase{PostDialect::linuxcnc, true}),
                         [](const auto& info) {
                           return std::string(lamina::post_dialect_name(info.param.dialect)) +
                                  (info.param.rtcp ? "_rtcp" : "_pivot");
                         });

TEST(PostRoundTrip, SignsOffsetAndPivotOfAnotherHead) {
  HeadKinematics head;
  head.rtcp = false;
  head.a_sign = -1;
  head.c_sign = -1;
  head.c_offset_rad = 90 * deg;
  head.pivot_mm = 210.0;
  for (PostDialect d : {PostDialect::grblhal, PostDialect::fanuc, PostDialect::linuxcnc}) {
    PostParams params;
    params.dialect = d;
    round_trip(post_test::make_toolpath(typical_sheet()), head, params);
  }
}

// An edge of 201 stations 0.5 mm apart on a 6 mm sheet whose tilt alternates 20° / 20° + step.
SheetToolpath alternating_edge(double step_deg) {
  ContourSpec edge;
  for (int k = 0; k <= 200; ++k) {
    const double tilt = (20.0 + (k % 2 ? step_deg : 0.0)) * deg;
    edge.stations.push_back({{100.0 + 0.5 * k, 100.0, 0.0}, tilted(tilt, -std::numbers::pi / 2)});
  }
  return make_toolpath({edge});
}

PostParams grblhal_pivot_params() {
  PostParams params;
  params.dialect = PostDialect::grblhal;
  params.angular_decimals = 3;
  return params;
}

std::size_t a_words(const std::string& text) {
  std::size_t n = 0;
  for (const std::string& line : split_lines(text))
    if (line.find('A') != std::string::npos && line.front() != '(') ++n;
  return n;
}

// A bevel's stations alternate: at a mesh's vertices and between them the tilt differs by a few
// thousandths of a degree. A pivot post holds A and C while the far face stays within a linear
// step (here 0.006° on a 6 mm sheet is 0.63 µm), so A is written once along the edge, not on
// every line; X Y Z follow the angle held, so the tip is where planned. Off, A alternates.
TEST(PostRoundTrip, APivotPostHoldsARotaryWordWhileTheFarFaceStaysWithinAStep) {
  const SheetToolpath tp = alternating_edge(0.006);
  ASSERT_DOUBLE_EQ(tp.thickness_mm, 6.0);
  HeadKinematics head;
  head.rtcp = false;
  PostParams params = grblhal_pivot_params();
  const RoundTrip held = round_trip(tp, head, params);  // tip within 1 µm, far face within 1 µm
  params.hold_rotary_within_step = false;
  const RoundTrip every = round_trip(tp, head, params);
  ASSERT_GT(every.posted.five_axis_moves, 150u);
  EXPECT_GT(a_words(every.posted.text), 190u);
  EXPECT_LT(a_words(held.posted.text), 12u);  // the rapids and the lead-in turn, then one A
  std::printf("alternating bevel, grblhal pivot: %zu bytes held, %zu written every time\n", held.posted.text.size(),
              every.posted.text.size());
  // Each of the ~200 lines loses its A word and the Z that A moved.
  EXPECT_LT(held.posted.text.size() + 200 * 8, every.posted.text.size());
}

// Stations alternating 0.016° in tilt on a 6 mm sheet: each is outside the other's window (1 µm
// at the far face is 0.0095°), so the last A written could never be held, but their windows
// overlap and one A between them serves the whole run (issue 22: the knob's 2.5 mm layers).
TEST(PostRoundTrip, APivotPostWritesOneAForARunOfAlternatingStationsWhoseWindowsOverlap) {
  const SheetToolpath tp = alternating_edge(0.016);
  ASSERT_DOUBLE_EQ(tp.thickness_mm, 6.0);
  HeadKinematics head;
  head.rtcp = false;
  const RoundTrip held = round_trip(tp, head, grblhal_pivot_params());  // tip and far face within 1 µm
  EXPECT_LT(a_words(held.posted.text), 12u) << held.posted.text.substr(0, 600);  // the rapids and the lead-in turn, then one A
}

TEST(PostRoundTrip, CompactTypicalCutWithRtcpIsUnder30BytesPerFiveAxisMove) {
  // A bevelled outline: a cone of 1 mm segments at 25° tilt, tip on the top face.
  HeadKinematics head;
  head.rtcp = true;
  PostParams params;
  params.dialect = PostDialect::fanuc;
  const SheetToolpath tp = post_test::make_toolpath({post_test::cone({250, 250}, 160, 25 * deg, 1.0, 1000)});
  const RoundTrip rt = round_trip(tp, head, params);
  ASSERT_GT(rt.posted.five_axis_moves, 900u);
  const double per_move = static_cast<double>(rt.posted.five_axis_bytes) / static_cast<double>(rt.posted.five_axis_moves);
  std::printf("bevelled outline, fanuc RTCP: %zu five-axis moves, %zu bytes, %.2f bytes/move\n",
              rt.posted.five_axis_moves, rt.posted.five_axis_bytes, per_move);
  EXPECT_LE(per_move, 30.0);
}

TEST(PostRoundTrip, LimitedCRewindsOnlyInRapids) {
  HeadKinematics head;
  head.rtcp = false;
  head.c_min_rad = -200 * deg;
  head.c_max_rad = 200 * deg;
  // Three full turns the same way: unwound C would reach 1260°. Each starts at C = 180° (the tip at
  // φ = 90° on its circle, C = φ + 90°), so a turn fits in ±200° only as −180° … 180°.
  const double start = std::numbers::pi / 2;
  const SheetToolpath tp = post_test::make_toolpath({post_test::cone({100, 100}, 30, 30 * deg, 1.0, 120, start),
                                                     post_test::cone({200, 100}, 30, 30 * deg, 1.0, 120, start),
                                                     post_test::cone({300, 100}, 30, 30 * deg, 1.0, 120, start)});
  for (PostDialect d : {PostDialect::grblhal, PostDialect::fanuc, PostDialect::linuxcnc}) {
    PostParams params;
    params.dialect = d;
    const RoundTrip rt = round_trip(tp, head, params);
    const auto& lines = rt.read.motions;
    int rewinds = 0;
    for (std::size_t k = 0; k < lines.size(); ++k) {
      EXPECT_LE(std::abs(lines[k].c_deg), 200.0 + 1e-9) << lines[k].text;
      if (k > 0 && std::abs(lines[k].c_deg - lines[k - 1].c_deg) > 180.0) {
        ++rewinds;
        EXPECT_EQ(lines[k].motion, 0) << "rewind on a cutting line: " << lines[k].text;
        EXPECT_FALSE(lines[k].jet_on) << lines[k].text;
        EXPECT_GE(lines[k].z, lines[k - 1].z - 1e-9) << "rewind below travel height: " << lines[k].text;
      }
    }
    EXPECT_GE(rewinds, 2);
  }
}

TEST(PostErrors, ContourWhoseCTravelDoesNotFitIsNamed) {
  HeadKinematics head;
  head.c_min_rad = -200 * deg;
  head.c_max_rad = 200 * deg;
  const SheetToolpath tp = post_test::make_toolpath(
      {post_test::vertical_rectangle({0, 0}, 10, 10, 2), post_test::cone({100, 100}, 30, 30 * deg, 1.5, 120)});
  PostParams params;
  params.dialect = PostDialect::linuxcnc;
  auto posted = lamina::post_program(tp, head, params);
  ASSERT_FALSE(posted);
  EXPECT_NE(posted.error().message.find("contour 1"), std::string::npos) << posted.error().message;
}

TEST(PostErrors, UnreachableTiltIsNamedWithItsContour) {
  HeadKinematics head;
  head.rtcp = false;
  const SheetToolpath tp =
      post_test::make_toolpath({post_test::vertical_rectangle({0, 0}, 10, 10, 2), post_test::cone({50, 50}, 10, 20 * deg, 1, 36),
                                post_test::cone({100, 100}, 10, 70 * deg, 1.0, 36)});
  PostParams params;
  params.dialect = PostDialect::grblhal;
  auto posted = lamina::post_program(tp, head, params);
  ASSERT_FALSE(posted);
  EXPECT_NE(posted.error().message.find("contour 2"), std::string::npos) << posted.error().message;
  EXPECT_NE(posted.error().message.find("70.000"), std::string::npos) << posted.error().message;
}

TEST(PostErrors, GrblhalHasNoRtcp) {
  HeadKinematics head;
  head.rtcp = true;
  PostParams params;
  params.dialect = PostDialect::grblhal;
  auto posted = lamina::post_program(post_test::make_toolpath(typical_sheet()), head, params);
  ASSERT_FALSE(posted);
  EXPECT_EQ(posted.error().code, lamina::ErrorCode::unsupported);
}

}  // namespace
