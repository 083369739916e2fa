// The time model and geometry of one block.
//   G0: every axis at its rapid rate, the slowest one sets the time.
//   G1/G2/G3 in G94: path length / feed, the feed clamped to max_feed. The path length is the
//     XYZ distance in mm when a linear axis moves, else the A/C distance in degrees (Grbl and
//     LinuxCNC both time a rotary-only move by its degrees).
//   G1/G2/G3 in G93: 1/F minutes; F must be on the line (RS274NGC, Grbl). G0 in G93 needs no
//     F here (Grbl 1.1 asks for one through a known bug; our posts never send G0 in G93).
//   Any feed move also takes at least its rapid time: no axis runs faster than its rapid rate.
//   G4: P seconds. G28: two rapids, to the intermediate point and on to the stored position.
//   Everything else: zero time.
// Arcs run in the XY plane (G17, the only plane here) with I/J centre offsets (relative to the
// start, Grbl's default G91.1) or R (negative R: the arc over 180°); Z, A, C move linearly
// along them (helix). The checks are grblHAL's gc_execute_block ones, in its order.
#include "machine_plan.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace lamina::sim::detail {
namespace {

constexpr double kMmPerInch = 25.4;
constexpr double kTwoPi = 2 * std::numbers::pi;

double linear_distance_mm(const AxisValues& a, const AxisValues& b) {
  return std::hypot(b[0] - a[0], b[1] - a[1], b[2] - a[2]);
}
double rotary_distance_deg(const AxisValues& a, const AxisValues& b) {
  return std::hypot(b[3] - a[3], b[4] - a[4]);
}
// What a straight move is timed and decelerated on: mm, or degrees for a rotary-only move.
double path_measure(const AxisValues& a, const AxisValues& b) {
  const double lin = linear_distance_mm(a, b);
  return lin > 0 ? lin : rotary_distance_deg(a, b);
}
// Time with every axis at its rapid rate: the slowest axis decides.
double rapid_time_s(const AxisValues& a, const AxisValues& b, const MachineConfig& config) {
  double t_s = 0;
  for (int i = 0; i < kAxisCount; ++i)
    t_s = std::max(t_s, std::abs(b[i] - a[i]) / config.rapid_per_min[i] * 60.0);
  return t_s;
}

// Arc geometry from I/J or R, checked as grblHAL's gc_execute_block does. Fills centre, radius,
// start angle and signed sweep; `straight` when grblHAL's arc degenerates to its final mc_line
// (an R arc whose ends meet in XY while another axis moves; I0 J0 to the start point).
GrblStatus plan_arc(const Block& block, double unit, PlannedBlock& p, bool& straight) {
  const bool cw = p.kind == MotionMode::arc_cw;
  const double sx = p.start[0], sy = p.start[1], ex = p.target[0], ey = p.target[1];
  if (!block.axis_words[0] && !block.axis_words[1]) return GrblStatus::no_axis_words_in_plane;
  straight = false;
  if (block.r_mm) {
    // Radius mode consumes only R: I, J, K beside it are unused words (grblHAL's last check,
    // so an arc error on the same line wins; the order matters little for a line this wrong).
    if (block.i_mm || block.j_mm || block.k_mm) return GrblStatus::unused_words;
    // grblHAL compares the whole position vector: ends that meet only in XY are no error.
    if (p.start == p.target) return GrblStatus::invalid_target;
    const double r = *block.r_mm * unit;
    const double d = std::hypot(ex - sx, ey - sy);
    if (d < 1e-9) {
      straight = true;  // grblHAL divides by d = 0: a NaN centre, mc_arc plans no segment
      return GrblStatus::ok;
    }
    if (4 * r * r - d * d < -1e-9 * r * r) return GrblStatus::arc_radius_error;
    const double h = std::sqrt(std::max(0.0, r * r - d * d / 4));
    // The centre lies on the chord's bisector: left of the chord for a CCW arc under 180°,
    // right for CW; a negative R asks for the other (major) arc.
    const double ux = (ex - sx) / d, uy = (ey - sy) / d;
    const double side = (cw ? -1.0 : 1.0) * (r > 0 ? 1.0 : -1.0);
    p.center_x = (sx + ex) / 2 - side * h * uy;
    p.center_y = (sy + ey) / 2 + side * h * ux;
    p.radius = std::abs(r);
  } else {
    // Offset mode consumes I, J and K (K means nothing in the XY plane and is ignored).
    if (!block.i_mm && !block.j_mm) return GrblStatus::no_offsets_in_plane;
    p.center_x = sx + block.i_mm.value_or(0) * unit;
    p.center_y = sy + block.j_mm.value_or(0) * unit;
    p.radius = std::hypot(sx - p.center_x, sy - p.center_y);
    // The end must lie on the same circle: grblHAL's tolerance, 0.005 mm, or 0.5 mm and 0.1 % of r.
    const double delta = std::abs(std::hypot(ex - p.center_x, ey - p.center_y) - p.radius);
    if (delta > 0.005 && (delta > 0.5 || delta > 0.001 * p.radius)) return GrblStatus::invalid_target;
    if (p.radius < 1e-9) {
      straight = true;  // I0 J0: mc_arc plans no segment, only its final line
      return GrblStatus::ok;
    }
  }
  p.start_angle = std::atan2(sy - p.center_y, sx - p.center_x);
  double sweep = std::atan2(ey - p.center_y, ex - p.center_x) - p.start_angle;
  // Same start and end angle: a full circle (I/J form).
  if (cw) {
    if (sweep >= -1e-9) sweep -= kTwoPi;
  } else if (sweep <= 1e-9) {
    sweep += kTwoPi;
  }
  p.sweep = sweep;
  p.path_length = std::hypot(p.radius * std::abs(sweep), p.target[2] - p.start[2]);
  return GrblStatus::ok;
}

// G28 (grblHAL's NonModal_GoHome_0): the axis words give an intermediate point (in the modal
// distance mode), then those axes go to the stored position; without axis words every axis
// goes there straight. Both legs are rapids.
void plan_go_home(bool any_axis, const std::array<std::optional<double>, kAxisCount>& words,
                  const MachineConfig& config, PlannedBlock& p) {
  p.kind = MotionMode::rapid;
  AxisValues home = p.start;
  for (int i = 0; i < kAxisCount; ++i)
    if (!any_axis || words[static_cast<std::size_t>(i)]) home[i] = config.g28_position[i];
  if (any_axis) p.via = p.target;
  p.target = home;
}

// The modal state after the block's mode words (units, distance, feed mode, feed, motion).
ModalState next_modal(const ModalState& modal, const Block& block) {
  ModalState m = modal;
  if (block.set_inches) m.inches = *block.set_inches;
  if (block.set_relative) m.relative = *block.set_relative;
  if (block.set_inverse_time && *block.set_inverse_time != m.inverse_time) {
    m.inverse_time = *block.set_inverse_time;
    m.feed_mm_per_min.reset();  // a G94 feed does not survive a G93 stretch (Grbl, LinuxCNC)
  }
  const double unit = m.inches ? kMmPerInch : 1.0;
  if (block.feed_word && !m.inverse_time) m.feed_mm_per_min = *block.feed_word * unit;
  if (block.motion == MotionMode::rapid || block.motion == MotionMode::linear ||
      block.motion == MotionMode::arc_cw || block.motion == MotionMode::arc_ccw)
    m.motion = block.motion;
  return m;
}

// The move's duration and path length (rapids at the axes' rates, feeds at F or inverse time).
GrblStatus time_move(const Block& block, const ModalState& m, const AxisValues& from, bool arc,
                     const MachineConfig& config, PlannedBlock& p) {
  switch (p.kind) {
    case MotionMode::none: break;
    case MotionMode::dwell: p.duration_s = *block.dwell_s; break;
    case MotionMode::rapid:
      if (p.via) {
        p.duration_s = rapid_time_s(from, *p.via, config) + rapid_time_s(*p.via, p.target, config);
        p.path_length = path_measure(from, *p.via) + path_measure(*p.via, p.target);
      } else {
        p.duration_s = rapid_time_s(from, p.target, config);
        p.path_length = path_measure(from, p.target);
      }
      break;
    case MotionMode::linear: case MotionMode::arc_cw: case MotionMode::arc_ccw: {
      if (!arc) p.path_length = path_measure(from, p.target);
      if (m.inverse_time) {
        if (!block.feed_word || *block.feed_word <= 0) return GrblStatus::undefined_feed_rate;
        p.duration_s = 60.0 / *block.feed_word;
      } else {
        if (!m.feed_mm_per_min || *m.feed_mm_per_min <= 0) return GrblStatus::undefined_feed_rate;
        const double feed = std::min(*m.feed_mm_per_min, config.max_feed_mm_per_min);
        p.duration_s = p.path_length / feed * 60.0;
      }
      p.duration_s = std::max(p.duration_s, rapid_time_s(from, p.target, config));
      break;
    }
  }
  return GrblStatus::ok;
}

}  // namespace

GrblStatus plan_block(const Block& block, ModalState& modal, const AxisValues& from,
                      const MachineConfig& config, PlannedBlock& out) {
  const ModalState m = next_modal(modal, block);
  const double unit = m.inches ? kMmPerInch : 1.0;
  PlannedBlock p;
  p.jet_on = block.jet_on;
  p.spindle = block.spindle;
  p.coolant = block.coolant;
  p.program_end = block.program_end;
  p.line_number = block.line_number;
  p.start = from;
  p.target = from;

  bool any_axis = false;
  for (int i = 0; i < kAxisCount; ++i) {
    const auto& word = block.axis_words[static_cast<std::size_t>(i)];
    if (!word) continue;
    any_axis = true;
    const double v = *word * (i < 3 ? unit : 1.0);  // A and C are degrees in either unit mode
    // G53 (grblHAL's NonModal_AbsoluteOverride): machine coordinates, absolute even in G91.
    // This machine has no work offsets, so they are the program's coordinates otherwise.
    p.target[i] = m.relative && !block.machine_coords ? from[i] + v : v;
  }
  if (block.machine_coords && m.motion != MotionMode::rapid && m.motion != MotionMode::linear)
    return GrblStatus::g53_invalid_motion_mode;
  // Grbl moves only when axis words are present; a motion code alone just sets the mode.
  if (block.motion == MotionMode::dwell) p.kind = MotionMode::dwell;
  else if (block.go_home) plan_go_home(any_axis, block.axis_words, config, p);
  else if (any_axis) p.kind = m.motion;
  bool arc = p.kind == MotionMode::arc_cw || p.kind == MotionMode::arc_ccw;
  if (!arc && (block.i_mm || block.j_mm || block.k_mm || block.r_mm)) return GrblStatus::unused_words;
  if (arc) {
    bool straight = false;
    if (const GrblStatus s = plan_arc(block, unit, p, straight); s != GrblStatus::ok) return s;
    if (straight) {
      p.kind = MotionMode::linear;  // timed as the move grblHAL ends up making
      arc = false;
    }
  }
  if (const GrblStatus s = time_move(block, m, from, arc, config, p); s != GrblStatus::ok) return s;
  if (p.path_length > 0 && p.duration_s > 0) p.feed_mm_per_min = p.path_length / p.duration_s * 60.0;
  if (p.kind != MotionMode::dwell && p.duration_s <= 0) p.path_length = 0;
  // grblHAL's last check: a value word nothing used (B on this XYZAC machine, …).
  if (block.unused_word) return GrblStatus::unused_words;

  modal = m;
  out = std::move(p);
  return GrblStatus::ok;
}

namespace {
AxisValues lerp(const AxisValues& a, const AxisValues& b, double s) {
  AxisValues out;
  for (int i = 0; i < kAxisCount; ++i) out[i] = a[i] + s * (b[i] - a[i]);
  return out;
}
}  // namespace

AxisValues interpolate(const PlannedBlock& b, double s) {
  if (s >= 1) return b.target;
  if (s <= 0) return b.start;
  if (b.via) {
    // Simplification: the legs share the path fraction by length, not by their rapid times.
    const double first = path_measure(b.start, *b.via), total = first + path_measure(*b.via, b.target);
    const double at = s * total;
    if (at <= first && first > 0) return lerp(b.start, *b.via, at / first);
    return lerp(*b.via, b.target, total > first ? (at - first) / (total - first) : 1.0);
  }
  AxisValues out;
  for (int i = 0; i < kAxisCount; ++i) out[i] = b.start[i] + s * (b.target[i] - b.start[i]);
  if (b.kind == MotionMode::arc_cw || b.kind == MotionMode::arc_ccw) {
    const double angle = b.start_angle + s * b.sweep;
    out[0] = b.center_x + b.radius * std::cos(angle);
    out[1] = b.center_y + b.radius * std::sin(angle);
  }
  return out;
}

bool within_soft_limits(const PlannedBlock& b, const MachineConfig& config) {
  // Only moves are checked: a comment or M-code must not alarm a machine that powered up
  // outside its limits (it may still move back in).
  if (b.kind == MotionMode::none || b.kind == MotionMode::dwell) return true;
  auto inside = [&config](const AxisValues& p) {
    for (int i = 0; i < kAxisCount; ++i)
      if (p[i] < config.soft_min[i] || p[i] > config.soft_max[i]) return false;
    return true;
  };
  if (!inside(b.target)) return false;
  if (b.via && !inside(*b.via)) return false;  // G28's legs are straight: their ends decide
  if (b.kind == MotionMode::arc_cw || b.kind == MotionMode::arc_ccw) {
    // An arc can bulge past a limit between its ends: sample it (every ≤ 5°).
    const int n = std::max(4, static_cast<int>(std::ceil(std::abs(b.sweep) / (std::numbers::pi / 36))));
    for (int k = 1; k < n; ++k)
      if (!inside(interpolate(b, static_cast<double>(k) / n))) return false;
  }
  return true;
}

}  // namespace lamina::sim::detail
