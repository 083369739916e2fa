#pragma once
// The round trip every post test makes: post → the test's own G-code reader → the test's own
// forward kinematics → the planned tip and tool axis at every move end, plus the program's modal,
// jet, C-continuity and contour-marker rules. Used on hand-built toolpaths and on the knob's sheets.
#include "gcode_reader.hpp"

#include "lamina/core/post.hpp"

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

namespace post_test {

using lamina::HeadKinematics;
using lamina::MoveKind;
using lamina::PostDialect;
using lamina::PostParams;
using lamina::SheetToolpath;


using lamina::HeadKinematics;
using lamina::MoveKind;
using lamina::PostDialect;
using lamina::PostParams;
using lamina::SheetToolpath;

inline constexpr double deg = std::numbers::pi / 180.0;
inline constexpr double tip_tolerance_mm = 1e-3;     // 1 µm
inline constexpr double axis_tolerance_deg = 0.01;
inline constexpr double time_tolerance = 0.005;       // 0.5 %

struct TipAxis {
  Eigen::Vector3d tip, axis;
};

// Forward kinematics written from the definition (rotation matrices), not from kinematics.cpp:
// axis = Rz(c_sign·C + c_offset)·Rx(a_sign·A)·ẑ; without RTCP the program's X Y Z is the tip
// shifted by pivot·(axis − ẑ).
inline TipAxis forward(const gcode_reader::MotionLine& m, const HeadKinematics& h) {
  const Eigen::Matrix3d r = (Eigen::AngleAxisd(h.c_sign * m.c_deg * deg + h.c_offset_rad, Eigen::Vector3d::UnitZ()) *
                             Eigen::AngleAxisd(h.a_sign * m.a_deg * deg, Eigen::Vector3d::UnitX()))
                                .toRotationMatrix();
  const Eigen::Vector3d axis = r * Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d xyz(m.x, m.y, m.z);
  return {h.rtcp ? xyz : Eigen::Vector3d(xyz - h.pivot_mm * (axis - Eigen::Vector3d::UnitZ())), axis};
}

inline double angle_deg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b)) / deg;
}

// The axis as the wall sees it: where it meets the sheet's far face, the thickness below the tip.
// A pivot post may hold A and C while that point stays within half a linear step (thickness ×
// the angle's sine); a toolpath without a thickness is held to the angle.
inline double far_face_error_mm(const TipAxis& t, const lamina::ToolMove& m, double thickness_mm) {
  return thickness_mm * t.axis.cross(m.axis).norm();
}
inline bool axis_matches(const TipAxis& t, const lamina::ToolMove& m, double thickness_mm) {
  if (thickness_mm <= 0.0) return angle_deg(t.axis, m.axis) <= axis_tolerance_deg;
  return far_face_error_mm(t, m, thickness_mm) <= tip_tolerance_mm && angle_deg(t.axis, m.axis) <= 0.1;
}
inline bool matches(const TipAxis& t, const lamina::ToolMove& m, double thickness_mm) {
  return (t.tip - m.tip_mm).norm() <= tip_tolerance_mm && axis_matches(t, m, thickness_mm);
}

inline std::vector<std::string> split_lines(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) out.push_back(line);
  return out;
}

inline gcode_reader::Options reader_options(const PostParams& p) {
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
inline RoundTrip round_trip(const SheetToolpath& tp, const HeadKinematics& head, const PostParams& params) {
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
    if (next < lines.size() && matches(forward(lines[next], head), m, tp.thickness_mm)) {
      j = next;
      started = true;
    }
    EXPECT_TRUE(started) << "move " << i << " before any motion line";
    if (!started) continue;
    rt.line_of_move.push_back(j);
    const TipAxis t = forward(lines[j], head);
    EXPECT_LE((t.tip - m.tip_mm).norm(), tip_tolerance_mm)
        << "move " << i << " line " << lines[j].line << " " << lines[j].text;
    EXPECT_TRUE(axis_matches(t, m, tp.thickness_mm))
        << "move " << i << " line " << lines[j].text << ": axis " << angle_deg(t.axis, m.axis) << "° off, "
        << far_face_error_mm(t, m, tp.thickness_mm) << " mm at the far face";
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

}  // namespace post_test
