// post_program: a sheet's toolpath → G-code text. Machine axes come from post_axes.cpp, the
// dialect's framing from post_dialects.cpp, number text from gcode_words.cpp; this file drives the
// moves and keeps the modal state so that only words that change are written.
// Units: mm, s, rad in; mm, degrees, mm/min (G94) or 1/min (G93) out — converted here only.
#include "post/gcode_words.hpp"
#include "post/post_internal.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <numbers>
#include <optional>
#include <Eigen/Geometry>

namespace lamina {

namespace {

using post_detail::format_number;
using post_detail::format_significant;
using post_detail::deg_per_rad;
using post_detail::rounded_poses;

constexpr double s_per_min = 60.0;
// A feed move whose tip travels less than this is a pure reorientation: its G93 time comes from
// the arc the pivot travels instead (the tip distance would make it instantaneous).
constexpr double still_tip_mm = 1e-6;
constexpr int inverse_time_digits = 4;  // significant digits of an F word: ≤ 5e-4 relative, a tenth of the 0.5 % checked

enum class Motion : std::uint8_t { none, rapid, feed };

struct Writer {
  std::string text;
  std::size_t lines = 0;
  std::optional<Error> error;

  void emit(const std::string& line) {
    if (line.size() > post_detail::max_line_chars && !error)
      error = Error{ErrorCode::invalid_argument,
                    fmt::format("line {} is {} characters (limit {}): {}", lines + 1, line.size(),
                                post_detail::max_line_chars, line)};
    text += line;
    text += '\n';
    ++lines;
  }
};

std::string contour_marker(std::size_t index, const ToolContour& c) {
  // The part as the drawing labels it; an outline of -1 is a dowel hole.
  // No part at all: a test cut of a calibration coupon (coupon.hpp), named by its label.
  const std::string part = c.label.empty() ? fmt::format("PART {}", c.part) : c.label;
  std::string s = c.part < 0         ? fmt::format("CONTOUR {} {} TEST CUT", index, part)
                  : c.outline < 0    ? fmt::format("CONTOUR {} {} DOWEL", index, part)
                                     : fmt::format("CONTOUR {} {} OUTLINE {} PASS {}", index, part, c.outline, c.pass);
  if (c.is_hole) s += " HOLE";
  if (c.frees) s += " FREES";
  if (!c.closed) s += " OPEN";
  return "(" + post_detail::comment_text(s, post_detail::max_line_chars - 2) + ")";
}

constexpr std::array<char, 5> kAxisLetters{'X', 'Y', 'Z', 'A', 'C'};

// A pose's axis words as text, and which differ from what the controller last read.
struct AxisWords {
  std::array<std::string, 5> text;
  std::array<bool, 5> changed{};
  bool any_changed = false;
  bool turns = false;  // A or C changes
};

// The program as written so far and the controller's modal state it leaves: only words that
// change are written.
struct ProgramWriter {
  ProgramWriter(const SheetToolpath& t, const HeadKinematics& h, const PostParams& p, const std::vector<AxisPose>& ps)
      : toolpath(t), head(h), params(p), poses(ps) {}

  const SheetToolpath& toolpath;
  const HeadKinematics& head;
  const PostParams& params;
  const std::vector<AxisPose>& poses;
  const bool kp = post_detail::keeps_decimal_point(params.dialect);
  const std::string jet_on_line = post_detail::m_code_line(params.jet_on);
  const std::string jet_off_line = post_detail::m_code_line(params.jet_off);

  Writer w;
  PostedProgram out;
  Motion motion = Motion::none;
  bool inverse_time = false;                     // every preamble selects G94
  std::optional<std::string> feed_word;          // F as last printed; none: undefined for the next G1
  std::array<std::optional<std::string>, 5> at;  // X Y Z A C as the controller last read them
  bool force = true;                             // write every axis word on the next motion line
  bool jet = false;
  std::optional<std::size_t> contour;            // the contour whose marker came last

  void motion_line(const std::string& line, bool five_axis) {
    w.emit(line);
    ++out.motion_lines;
    if (jet && contour) out.contour_last_cut_lines[*contour] = w.lines;
    if (five_axis) {
      ++out.five_axis_moves;
      out.five_axis_bytes += line.size() + 1;
    }
  }

  // The program can be resumed at the marker: the next lines restate the modal words.
  void marker(std::size_t ci) {
    if (!contour) out.setup_lines = w.lines;
    w.emit(contour_marker(ci, toolpath.contours[ci]));
    out.contour_lines[ci] = w.lines;
    contour = ci;
    force = true;
    motion = Motion::none;
    feed_word.reset();
  }

  void set_jet(bool on) {
    if (on == jet) return;
    w.emit(on ? jet_on_line : jet_off_line);
    jet = on;
  }

  AxisWords words_of(const AxisPose& p) const {
    AxisWords a;
    a.text = {format_number(p.x_mm, params.linear_decimals, kp), format_number(p.y_mm, params.linear_decimals, kp),
              format_number(p.z_mm, params.linear_decimals, kp),
              format_number(p.a_rad * deg_per_rad, params.angular_decimals, kp),
              format_number(p.c_rad * deg_per_rad, params.angular_decimals, kp)};
    for (std::size_t k = 0; k < 5; ++k) {
      a.changed[k] = !at[k] || *at[k] != a.text[k];
      a.any_changed = a.any_changed || a.changed[k];
    }
    a.turns = a.changed[3] || a.changed[4];
    return a;
  }

  // Appends the words that change (all after a marker); true when A or C is among them.
  bool axis_words(std::string& line, const AxisWords& a) {
    bool five_axis = false;
    for (std::size_t k = 0; k < 5; ++k) {
      if (!(a.changed[k] || force)) continue;
      line += kAxisLetters[k];
      line += a.text[k];
      at[k] = a.text[k];
      five_axis = five_axis || k >= 3;
    }
    force = false;
    return five_axis;
  }

  void rapid_to(const AxisWords& a) {
    std::string line;
    if (inverse_time) {
      line += "G94";  // never G0 in G93: Grbl 1.1 then wants an F on the G0
      inverse_time = false;
      feed_word.reset();  // the F is undefined after G93 → G94 (Grbl, LinuxCNC)
    }
    if (motion != Motion::rapid) line += "G0";
    motion = Motion::rapid;
    const bool five = axis_words(line, a);
    motion_line(line, five);
  }

  // The move's time: the toolpath's duration_s (the longer of the jet's travel at the top and the
  // bottom face); a toolpath without durations: the tip's distance at the feed.
  double move_seconds(std::size_t i, double tip_distance) const {
    const ToolMove& m = toolpath.moves[i];
    if (m.duration_s > 0.0) return m.duration_s;
    double distance = tip_distance;
    if (distance < still_tip_mm && i > 0) {  // a turn about the tip: the pivot's arc
      const TipPose a = forward_kinematics(poses[i - 1], head), b = forward_kinematics(poses[i], head);
      distance = head.pivot_mm * std::acos(std::clamp(a.axis.dot(b.axis), -1.0, 1.0));
    }
    return std::max(distance, still_tip_mm) / m.feed_mm_per_s;
  }

  // The F word of a feed move, switching G93/G94 in `line` as the move needs.
  std::string feed_of(std::size_t i, const AxisWords& a, std::string& line) {
    const ToolMove& m = toolpath.moves[i];
    const Eigen::Vector3d from = i > 0 ? toolpath.moves[i - 1].tip_mm : m.tip_mm;
    const double tip_distance = (m.tip_mm - from).norm();
    const double minutes = move_seconds(i, tip_distance) / s_per_min;
    if (!head.rtcp && a.turns) {
      // Inverse time: F = 1 / minutes of the move.
      if (!inverse_time) line += "G93";
      inverse_time = true;
      return format_significant(1.0 / minutes, inverse_time_digits, 3, kp);
    }
    // mm/min of the tip (RTCP: the controller holds the tip's speed; without RTCP the head does
    // not turn, so X Y Z move as the tip). A turn about a still tip keeps the cutting feed.
    const double mm_per_min = tip_distance >= still_tip_mm ? tip_distance / minutes : m.feed_mm_per_s * s_per_min;
    if (inverse_time) {
      line += "G94";
      inverse_time = false;
      feed_word.reset();
    }
    return format_significant(mm_per_min, inverse_time_digits, params.feed_decimals, kp);
  }

  // Feed moves: lead-in, cut, lead-out.
  std::expected<void, Error> feed_move(std::size_t i, const AxisWords& a) {
    const ToolMove& m = toolpath.moves[i];
    if (!(m.feed_mm_per_s > 0.0) || !std::isfinite(m.feed_mm_per_s))
      return std::unexpected(Error{ErrorCode::invalid_argument,
                                   fmt::format("move {}: feed {} mm/s is not positive", i, m.feed_mm_per_s)});
    if (m.jet_on) set_jet(true);
    if (!a.any_changed && !force) return {};  // nothing the controller would see
    std::string line;
    const std::string f = feed_of(i, a, line);
    if (motion != Motion::feed) line += "G1";
    motion = Motion::feed;
    const bool five = axis_words(line, a);
    if (inverse_time || !feed_word || *feed_word != f) {
      line += 'F';
      line += f;
      feed_word = inverse_time ? std::nullopt : std::optional<std::string>(f);
    }
    motion_line(line, five);
    return {};
  }

  std::expected<void, Error> move(std::size_t i) {
    const ToolMove& m = toolpath.moves[i];
    if (!m.jet_on && jet) set_jet(false);
    const AxisWords a = words_of(poses[i]);
    if (m.kind == MoveKind::pierce) {
      if (a.any_changed || force) rapid_to(a);  // the pierce point, jet still off
      set_jet(true);
      if (m.dwell_s > 0.0) w.emit(post_detail::dwell_line(m.dwell_s, params));
      return {};
    }
    if (m.kind == MoveKind::rapid) {
      if (a.any_changed || force) rapid_to(a);
      return {};
    }
    return feed_move(i, a);
  }
};

}  // namespace

std::expected<PostedProgram, Error> post_program(const SheetToolpath& toolpath, const HeadKinematics& head,
                                                 const PostParams& params) {
  if (auto ok = post_detail::check_post_setup(head, params); !ok) return std::unexpected(ok.error());
  auto planned = post_detail::plan_machine_axes(toolpath, head);
  if (!planned) return std::unexpected(planned.error());
  const std::vector<AxisPose> poses = rounded_poses(toolpath, head, params, std::move(*planned));

  std::multimap<std::size_t, std::size_t> contour_at;  // first move → contour index
  for (std::size_t ci = 0; ci < toolpath.contours.size(); ++ci) contour_at.emplace(toolpath.contours[ci].first_move, ci);

  ProgramWriter p{toolpath, head, params, poses};
  p.out.contour_lines.assign(toolpath.contours.size(), 0);
  p.out.contour_last_cut_lines.assign(toolpath.contours.size(), 0);
  for (const std::string& line : post_detail::program_start(head, params)) p.w.emit(line);
  for (std::size_t i = 0; i < toolpath.moves.size(); ++i) {
    for (auto [it, end] = contour_at.equal_range(i); it != end; ++it) p.marker(it->second);
    if (auto ok = p.move(i); !ok) return std::unexpected(ok.error());
  }
  p.set_jet(false);
  for (const std::string& line : post_detail::program_end(head, params)) p.w.emit(line);
  if (p.w.error) return std::unexpected(*p.w.error);

  p.out.text = std::move(p.w.text);
  p.out.lines = p.w.lines;
  p.out.poses = poses;
  return std::move(p.out);
}

}  // namespace lamina
