// post_program: a sheet's toolpath → G-code text. Machine axes come from post_axes.cpp, the
// dialect's framing from post_dialects.cpp, number text from gcode_words.cpp; this file drives the
// moves and keeps the modal state so that only words that change are written.
// Units: mm, s, rad in; mm, degrees, mm/min (G94) or 1/min (G93) out — converted here only.
#include "gcode_words.hpp"
#include "post_internal.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <numbers>
#include <optional>

namespace lamina {

namespace {

using post_detail::format_number;
using post_detail::format_significant;

constexpr double deg_per_rad = 180.0 / std::numbers::pi;
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
  const std::string part = c.label.empty() ? fmt::format("PART {}", c.part) : c.label;
  std::string s = c.outline < 0 ? fmt::format("CONTOUR {} {} DOWEL", index, part)
                                : fmt::format("CONTOUR {} {} OUTLINE {} PASS {}", index, part, c.outline, c.pass);
  if (c.is_hole) s += " HOLE";
  if (c.frees) s += " FREES";
  if (!c.closed) s += " OPEN";
  return "(" + post_detail::comment_text(s, post_detail::max_line_chars - 2) + ")";
}

}  // namespace

std::expected<PostedProgram, Error> post_program(const SheetToolpath& toolpath, const HeadKinematics& head,
                                                 const PostParams& params) {
  if (auto ok = post_detail::check_post_setup(head, params); !ok) return std::unexpected(ok.error());
  auto planned = post_detail::plan_machine_axes(toolpath, head);
  if (!planned) return std::unexpected(planned.error());
  // The controller reads A and C rounded to angular_decimals: without RTCP, X Y Z are computed from
  // those rounded angles, so the tip lands where planned (to the linear rounding).
  std::vector<AxisPose> poses = std::move(*planned);
  if (!head.rtcp) {
    const double step = std::pow(10.0, params.angular_decimals);
    for (std::size_t i = 0; i < poses.size(); ++i) {
      AxisPose& p = poses[i];
      p.a_rad = std::round(p.a_rad * deg_per_rad * step) / step / deg_per_rad;
      p.c_rad = std::round(p.c_rad * deg_per_rad * step) / step / deg_per_rad;
      const Eigen::Vector3d xyz = toolpath.moves[i].tip_mm +
                                  head.pivot_mm * (tool_axis_at(p.a_rad, p.c_rad, head) - Eigen::Vector3d::UnitZ());
      p.x_mm = xyz.x();
      p.y_mm = xyz.y();
      p.z_mm = xyz.z();
    }
  }
  const std::vector<ToolMove>& moves = toolpath.moves;
  const bool kp = post_detail::keeps_decimal_point(params.dialect);
  const std::string jet_on_line = post_detail::m_code_line(params.jet_on);
  const std::string jet_off_line = post_detail::m_code_line(params.jet_off);

  std::multimap<std::size_t, std::size_t> contour_at;  // first move → contour index
  for (std::size_t ci = 0; ci < toolpath.contours.size(); ++ci) contour_at.emplace(toolpath.contours[ci].first_move, ci);

  PostedProgram out;
  out.contour_lines.assign(toolpath.contours.size(), 0);
  out.contour_last_cut_lines.assign(toolpath.contours.size(), 0);
  std::optional<std::size_t> contour;  // the contour whose marker came last
  Writer w;
  for (const std::string& line : post_detail::program_start(head, params)) w.emit(line);

  Motion motion = Motion::none;
  bool inverse_time = false;            // every preamble selects G94
  std::optional<std::string> feed_word;  // F as last printed; none: undefined for the next G1
  std::array<std::optional<std::string>, 5> at;  // X Y Z A C as the controller last read them
  bool force = true;                     // write every axis word on the next motion line
  bool jet = false;
  constexpr std::array<char, 5> letters{'X', 'Y', 'Z', 'A', 'C'};

  auto motion_line = [&](const std::string& line, bool five_axis) {
    w.emit(line);
    ++out.motion_lines;
    if (jet && contour) out.contour_last_cut_lines[*contour] = w.lines;
    if (five_axis) {
      ++out.five_axis_moves;
      out.five_axis_bytes += line.size() + 1;
    }
  };

  for (std::size_t i = 0; i < moves.size(); ++i) {
    const ToolMove& m = moves[i];
    const AxisPose& p = poses[i];
    for (auto [it, end] = contour_at.equal_range(i); it != end; ++it) {
      if (!contour) out.setup_lines = w.lines;
      w.emit(contour_marker(it->second, toolpath.contours[it->second]));
      out.contour_lines[it->second] = w.lines;
      contour = it->second;
      // The program can be resumed at the marker: the next lines restate the modal words.
      force = true;
      motion = Motion::none;
      feed_word.reset();
    }
    if (!m.jet_on && jet) {
      w.emit(jet_off_line);
      jet = false;
    }

    const std::array<std::string, 5> words{
        format_number(p.x_mm, params.linear_decimals, kp), format_number(p.y_mm, params.linear_decimals, kp),
        format_number(p.z_mm, params.linear_decimals, kp),
        format_number(p.a_rad * deg_per_rad, params.angular_decimals, kp),
        format_number(p.c_rad * deg_per_rad, params.angular_decimals, kp)};
    std::array<bool, 5> changed{};
    bool any_changed = false;
    for (std::size_t k = 0; k < 5; ++k) {
      changed[k] = !at[k] || *at[k] != words[k];
      any_changed = any_changed || changed[k];
    }
    const bool turns = changed[3] || changed[4];
    auto axis_words = [&](std::string& line) {
      bool five_axis = false;
      for (std::size_t k = 0; k < 5; ++k) {
        if (!(changed[k] || force)) continue;
        line += letters[k];
        line += words[k];
        at[k] = words[k];
        five_axis = five_axis || k >= 3;
      }
      force = false;
      return five_axis;
    };
    auto rapid_to = [&]() {
      std::string line;
      if (inverse_time) {
        line += "G94";  // never G0 in G93: Grbl 1.1 then wants an F on the G0
        inverse_time = false;
        feed_word.reset();  // the F is undefined after G93 → G94 (Grbl, LinuxCNC)
      }
      if (motion != Motion::rapid) line += "G0";
      motion = Motion::rapid;
      const bool five = axis_words(line);
      motion_line(line, five);
    };

    if (m.kind == MoveKind::pierce) {
      if (any_changed || force) rapid_to();  // the pierce point, jet still off
      if (!jet) {
        w.emit(jet_on_line);
        jet = true;
      }
      if (m.dwell_s > 0.0) w.emit(post_detail::dwell_line(m.dwell_s, params));
      continue;
    }
    if (m.kind == MoveKind::rapid) {
      if (any_changed || force) rapid_to();
      continue;
    }

    // Feed moves: lead-in, cut, lead-out.
    if (!(m.feed_mm_per_s > 0.0) || !std::isfinite(m.feed_mm_per_s))
      return std::unexpected(Error{ErrorCode::invalid_argument,
                                   fmt::format("move {}: feed {} mm/s is not positive", i, m.feed_mm_per_s)});
    if (m.jet_on && !jet) {
      w.emit(jet_on_line);
      jet = true;
    }
    if (!any_changed && !force) continue;  // nothing the controller would see
    std::string line;
    std::string f;
    // The move's time: the toolpath's duration_s (the longer of the jet's travel at the top and the
    // bottom face); a toolpath without durations: the tip's distance at the feed.
    const Eigen::Vector3d from = i > 0 ? moves[i - 1].tip_mm : m.tip_mm;
    const double tip_distance = (m.tip_mm - from).norm();
    double seconds = m.duration_s;
    if (!(seconds > 0.0)) {
      double distance = tip_distance;
      if (distance < still_tip_mm && i > 0) {  // a turn about the tip: the pivot's arc
        const TipPose a = forward_kinematics(poses[i - 1], head), b = forward_kinematics(p, head);
        distance = head.pivot_mm * std::acos(std::clamp(a.axis.dot(b.axis), -1.0, 1.0));
      }
      seconds = std::max(distance, still_tip_mm) / m.feed_mm_per_s;
    }
    const double minutes = seconds / s_per_min;
    if (!head.rtcp && turns) {
      // Inverse time: F = 1 / minutes of the move.
      f = format_significant(1.0 / minutes, inverse_time_digits, 3, kp);
      if (!inverse_time) line += "G93";
      inverse_time = true;
    } else {
      // mm/min of the tip (RTCP: the controller holds the tip's speed; without RTCP the head does
      // not turn, so X Y Z move as the tip). A turn about a still tip keeps the cutting feed.
      const double mm_per_min = tip_distance >= still_tip_mm ? tip_distance / minutes : m.feed_mm_per_s * s_per_min;
      f = format_significant(mm_per_min, inverse_time_digits, params.feed_decimals, kp);
      if (inverse_time) {
        line += "G94";
        inverse_time = false;
        feed_word.reset();
      }
    }
    if (motion != Motion::feed) line += "G1";
    motion = Motion::feed;
    const bool five = axis_words(line);
    if (inverse_time || !feed_word || *feed_word != f) {
      line += 'F';
      line += f;
      feed_word = inverse_time ? std::nullopt : std::optional<std::string>(f);
    }
    motion_line(line, five);
  }
  if (jet) w.emit(jet_off_line);
  for (const std::string& line : post_detail::program_end(head, params)) w.emit(line);
  if (w.error) return std::unexpected(*w.error);

  out.text = std::move(w.text);
  out.lines = w.lines;
  out.poses = poses;
  return out;
}

}  // namespace lamina
