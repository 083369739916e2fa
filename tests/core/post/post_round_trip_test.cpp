// Round trips: hand-built toolpaths → post (every dialect, RTCP and not) → the test's own G-code
// reader → the test's own forward kinematics → the planned tip and tool axis at every move end.
#include "gcode_reader.hpp"
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

using lamina::HeadKinematics;
using lamina::MoveKind;
using lamina::PostDialect;
using lamina::PostParams;
using lamina::SheetToolpath;

constexpr double deg = std::numbers::pi / 180.0;
constexpr double tip_tolerance_mm = 1e-3;     // 1 µm
constexpr double axis_tolerance_deg = 0.01;
constexpr double time_tolerance = 0.005;       // 0.5 %

struct TipAxis {
  Eigen::Vector3d tip, axis;
};

// Forward kinematics written from the definition (rotation matrices), not from kinematics.cpp:
// axis = Rz(c_sign·C + c_offset)·Rx(a_sign·A)·ẑ; without RTCP the program's X Y Z is the tip
// shifted by pivot·(axis − ẑ).
TipAxis forward(const gcode_reader::MotionLine& m, const HeadKinematics& h) {
  const Eigen::Matrix3d r = (Eigen::AngleAxisd(h.c_sign * m.c_deg * deg + h.c_offset_rad, Eigen::Vector3d::UnitZ()) *
                             Eigen::AngleAxisd(h.a_sign * m.a_deg * deg, Eigen::Vector3d::UnitX()))
                                .toRotationMatrix();
  const Eigen::Vector3d axis = r * Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d xyz(m.x, m.y, m.z);
  return {h.rtcp ? xyz : Eigen::Vector3d(xyz - h.pivot_mm * (axis - Eigen::Vector3d::UnitZ())), axis};
}

double angle_deg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b)) / deg;
}

bool matches(const TipAxis& t, const lamina::ToolMove& m) {
  return (t.tip - m.tip_mm).norm() <= tip_tolerance_mm && angle_deg(t.axis, m.axis) <= axis_tolerance_deg;
}

std::vector<std::string> split_lines(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) out.push_back(line);
  return out;
}

gcode_reader::Options reader_options(const PostParams& p) {
  gcode_reader::Options o;
  o.fanuc = p.dialect == PostDialect::fanuc;
  o.jet_on = p.jet_on;
  o.jet_off = p.jet_off;
  return o;
}

struct RoundTrip {
  lamina::PostedProgram posted;
  gcode_reader::Program read;
  std::vector<std::size_t> line_of_move;  // index into read.motions
  std::size_t g93_lines = 0;
};

// Posts, reads back, and checks every move end against the plan. limited_c: C jumps over 180°
// are allowed on rapids (the rewinds) only.
RoundTrip round_trip(const SheetToolpath& tp, const HeadKinematics& head, const PostParams& params) {
  RoundTrip rt;
  auto posted = lamina::post_program(tp, head, params);
  EXPECT_TRUE(posted) << (posted ? "" : posted.error().message);
  if (!posted) return rt;
  rt.posted = *posted;
  auto read = gcode_reader::read_gcode(posted->text, reader_options(params));
  EXPECT_TRUE(read) << (read ? "" : read.error()) << "\n" << posted->text.substr(0, 2000);
  if (!read) return rt;
  rt.read = *read;
  const auto& lines = rt.read.motions;
  EXPECT_EQ(posted->poses.size(), tp.moves.size());
  EXPECT_EQ(posted->motion_lines, lines.size());
  EXPECT_EQ(posted->lines, rt.read.lines);
  EXPECT_FALSE(rt.read.jet_at_end);
  EXPECT_FALSE(rt.read.tcp_at_end);

  // Walk the moves: each either has its own motion line (the next one) or left the machine where
  // it was (a pierce at the rapid's end, a zero move).
  std::size_t j = 0;
  bool started = false;
  for (std::size_t i = 0; i < tp.moves.size(); ++i) {
    const lamina::ToolMove& m = tp.moves[i];
    const std::size_t next = started ? j + 1 : 0;
    if (next < lines.size() && matches(forward(lines[next], head), m)) {
      j = next;
      started = true;
    }
    EXPECT_TRUE(started) << "move " << i << " before any motion line";
    if (!started) continue;
    rt.line_of_move.push_back(j);
    const TipAxis t = forward(lines[j], head);
    EXPECT_LE((t.tip - m.tip_mm).norm(), tip_tolerance_mm)
        << "move " << i << " line " << lines[j].line << " " << lines[j].text;
    EXPECT_LE(angle_deg(t.axis, m.axis), axis_tolerance_deg) << "move " << i << " line " << lines[j].text;
    EXPECT_LE(std::abs(lines[j].a_deg), 60.0 + 1e-9);
    const bool own_line = i == 0 || rt.line_of_move[i - 1] != j;
    const bool feed_move = m.kind == MoveKind::lead_in || m.kind == MoveKind::cut || m.kind == MoveKind::lead_out;
    if (feed_move && own_line) {
      const auto& l = lines[j];
      EXPECT_EQ(l.motion, 1) << l.text;
      EXPECT_TRUE(l.jet_on) << l.text;
      if (l.inverse_time) {
        ++rt.g93_lines;
        EXPECT_FALSE(head.rtcp) << "G93 with RTCP: " << l.text;
        const double minutes = 1.0 / l.f;
        EXPECT_NEAR(minutes * 60.0 / m.duration_s, 1.0, time_tolerance) << "move " << i << " " << l.text;
      } else {
        const double distance = (m.tip_mm - tp.moves[i - 1].tip_mm).norm();
        if (distance > 1e-3) {
          EXPECT_NEAR(distance / (l.f / 60.0) / m.duration_s, 1.0, time_tolerance) << "move " << i << " " << l.text;
        }
        if (!head.rtcp) {
          EXPECT_FALSE(l.has_rotary) << "G94 move turns the head: " << l.text;
        }
      }
    }
    if (m.kind == MoveKind::rapid && own_line) {
      EXPECT_EQ(lines[j].motion, 0) << lines[j].text;
      EXPECT_FALSE(lines[j].jet_on) << lines[j].text;
    }
    if (m.kind == MoveKind::pierce) {
      EXPECT_LT(j + 1, lines.size());
      if (j + 1 < lines.size()) {
        EXPECT_NEAR(lines[j + 1].dwell_before_s, m.dwell_s, 1e-9) << lines[j + 1].text;
        EXPECT_TRUE(lines[j + 1].jet_on);
      }
    }
  }
  EXPECT_EQ(j + 1, lines.size()) << "motion lines left over after the last move";

  // RTCP: Fanuc's G43.4 is on for every motion line.
  for (const auto& l : lines) EXPECT_EQ(l.tcp, head.rtcp && params.dialect == PostDialect::fanuc) << l.text;

  // C continuity, modal G93/G94.
  const bool limited_c = std::isfinite(head.c_min_rad) || std::isfinite(head.c_max_rad);
  for (std::size_t k = 1; k < lines.size(); ++k) {
    const double jump = std::abs(lines[k].c_deg - lines[k - 1].c_deg);
    if (!limited_c || lines[k].motion == 1) {
      EXPECT_LE(jump, 180.0 + 1e-9) << lines[k].text;
    }
    const bool says93 = lines[k].text.find("G93") != std::string::npos;
    const bool says94 = lines[k].text.find("G94") != std::string::npos;
    EXPECT_EQ(says93, lines[k].inverse_time && !lines[k - 1].inverse_time) << lines[k].text;
    EXPECT_EQ(says94, !lines[k].inverse_time && lines[k - 1].inverse_time) << lines[k].text;
  }

  // Contour markers.
  const std::vector<std::string> text_lines = split_lines(posted->text);
  EXPECT_EQ(posted->contour_lines.size(), tp.contours.size());
  for (std::size_t ci = 0; ci < posted->contour_lines.size(); ++ci) {
    const std::size_t n = posted->contour_lines[ci];
    EXPECT_GE(n, 1u);
    EXPECT_LE(n, text_lines.size());
    if (n < 1 || n > text_lines.size()) continue;
    EXPECT_EQ(text_lines[n - 1].rfind("(CONTOUR " + std::to_string(ci) + " ", 0), 0u) << text_lines[n - 1];
  }
  return rt;
}

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

struct Case {
  PostDialect dialect;
  bool rtcp;
};

class PostRoundTrip : public ::testing::TestWithParam<Case> {};

TEST_P(PostRoundTrip, EveryMoveEndIsThePlannedTipAndAxis) {
  const Case c = GetParam();
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
                         ::testing::Values(Case{PostDialect::grblhal, false}, Case{PostDialect::fanuc, false},
                                           Case{PostDialect::fanuc, true}, Case{PostDialect::linuxcnc, false},
                                           Case{PostDialect::linuxcnc, true}),
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
