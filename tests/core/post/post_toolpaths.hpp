#pragma once
// Hand-built sheet toolpaths for the post tests: rapids at safe height, pierce, lead-in, cut,
// lead-out, as the toolpath stage lays them out (tip on the sheet's top face, z = 0).
#include "lamina/core/toolpath.hpp"

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <vector>

namespace post_test {

struct Station {
  Eigen::Vector3d tip;
  Eigen::Vector3d axis;
};

struct ContourSpec {
  std::vector<Station> stations;  // pierce point first; at least 3 (pierce, …, lead-out end)
  double feed_mm_per_s = 5.0;
  int part = 0;
  bool is_hole = false;
};

inline Eigen::Vector3d tilted(double tilt_rad, double toward_rad) {
  return {std::sin(tilt_rad) * std::cos(toward_rad), std::sin(tilt_rad) * std::sin(toward_rad), std::cos(tilt_rad)};
}

// A cone cut: the tip goes round a circle `turns` times, the axis leaning outward by tilt (inward
// with a negative tilt) — C turns once per turn and crosses ±180° on every turn.
inline ContourSpec cone(Eigen::Vector2d center, double radius, double tilt_rad, double turns, int steps_per_turn,
                        double start_rad = 0.0) {
  ContourSpec c;
  const int steps = static_cast<int>(std::lround(turns * steps_per_turn));
  for (int k = 0; k <= steps; ++k) {
    const double phi = start_rad + 2.0 * std::numbers::pi * k / steps_per_turn;
    c.stations.push_back({{center.x() + radius * std::cos(phi), center.y() + radius * std::sin(phi), 0.0},
                          tilted(tilt_rad, phi)});
  }
  return c;
}

// A vertical rectangle (A = 0 throughout), corners subdivided.
inline ContourSpec vertical_rectangle(Eigen::Vector2d corner, double w, double h, int per_side) {
  ContourSpec c;
  const Eigen::Vector2d p[5] = {corner, corner + Eigen::Vector2d(w, 0), corner + Eigen::Vector2d(w, h),
                                corner + Eigen::Vector2d(0, h), corner};
  for (int s = 0; s < 4; ++s)
    for (int k = 0; k < per_side; ++k) {
      const Eigen::Vector2d q = p[s] + (p[s + 1] - p[s]) * (static_cast<double>(k) / per_side);
      c.stations.push_back({{q.x(), q.y(), 0.0}, Eigen::Vector3d::UnitZ()});
    }
  c.stations.push_back({{corner.x(), corner.y(), 0.0}, Eigen::Vector3d::UnitZ()});
  c.feed_mm_per_s = 12.0;
  return c;
}

// Random unit axes within max_tilt, random tips in a box: every move turns the head arbitrarily.
inline ContourSpec random_walk(unsigned seed, int n, double max_tilt_rad) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  ContourSpec c;
  Eigen::Vector3d tip(200.0, 150.0, 0.0);
  for (int k = 0; k < n; ++k) {
    const double tilt = max_tilt_rad * std::sqrt(u(rng));
    const double toward = 2.0 * std::numbers::pi * u(rng);
    c.stations.push_back({tip, tilted(tilt, toward)});
    tip += Eigen::Vector3d(20.0 * (u(rng) - 0.5), 20.0 * (u(rng) - 0.5), 0.0);
  }
  c.feed_mm_per_s = 3.0;
  return c;
}

// Where the jet line through tip along axis crosses the sheet's bottom face.
inline Eigen::Vector3d bottom_point(const Eigen::Vector3d& tip, const Eigen::Vector3d& axis, double thickness) {
  return tip - axis * (thickness / axis.z());
}

// The layout of toolpath.hpp: a contour's moves are the rapid over its pierce point at safe height,
// the rapid down, pierce, lead-in, cuts, lead-out and the rapid up. Cutting moves take the longer
// of the jet's travel at the top and bottom faces at the feed.
inline lamina::SheetToolpath make_toolpath(const std::vector<ContourSpec>& specs, double safe_z = 10.0) {
  using lamina::MoveKind;
  lamina::SheetToolpath tp;
  tp.thickness_mm = 6.0;
  constexpr double rapid_mm_per_s = 250.0;
  auto add = [&](MoveKind kind, const Eigen::Vector3d& tip, const Eigen::Vector3d& axis, double feed, bool jet,
                 int contour, double dwell = 0.0) {
    lamina::ToolMove m;
    m.kind = kind;
    m.tip_mm = tip;
    m.axis = axis.normalized();
    m.feed_mm_per_s = feed;
    m.jet_on = jet;
    m.contour = contour;
    m.dwell_s = dwell;
    if (!tp.moves.empty()) {
      const lamina::ToolMove& prev = tp.moves.back();
      const double top = (m.tip_mm - prev.tip_mm).norm();
      if (kind == MoveKind::rapid) {
        m.duration_s = top / rapid_mm_per_s;
      } else if (kind == MoveKind::pierce) {
        m.duration_s = dwell;
      } else {
        const double bottom = (bottom_point(m.tip_mm, m.axis, tp.thickness_mm) -
                               bottom_point(prev.tip_mm, prev.axis, tp.thickness_mm)).norm();
        m.duration_s = std::max(top, bottom) / feed;
      }
    }
    tp.moves.push_back(m);
  };
  const Eigen::Vector3d up(0, 0, safe_z);
  add(MoveKind::rapid, up, Eigen::Vector3d::UnitZ(), 0, false, -1);  // park
  for (std::size_t ci = 0; ci < specs.size(); ++ci) {
    const ContourSpec& s = specs[ci];
    const Station& first = s.stations.front();
    const int contour = static_cast<int>(ci);
    lamina::ToolContour tc;
    tc.part = s.part;
    tc.outline = contour;
    tc.pass = 0;
    tc.is_hole = s.is_hole;
    tc.closed = true;
    tc.frees = !s.is_hole;
    tc.pierce_mm = first.tip.head<2>();
    tc.first_move = tp.moves.size();
    add(MoveKind::rapid, Eigen::Vector3d(first.tip.x(), first.tip.y(), safe_z), first.axis, 0, false, contour);
    add(MoveKind::rapid, first.tip, first.axis, 0, false, contour);
    add(MoveKind::pierce, first.tip, first.axis, 0, true, contour, 1.25);
    for (std::size_t k = 1; k < s.stations.size(); ++k) {
      const MoveKind kind = k == 1 ? MoveKind::lead_in : k + 1 == s.stations.size() ? MoveKind::lead_out : MoveKind::cut;
      add(kind, s.stations[k].tip, s.stations[k].axis, s.feed_mm_per_s, true, contour);
    }
    const Station& last = s.stations.back();
    add(MoveKind::rapid, Eigen::Vector3d(last.tip.x(), last.tip.y(), safe_z), last.axis, 0, false, contour);
    tc.end_move = tp.moves.size();
    tp.contours.push_back(tc);
  }
  add(MoveKind::rapid, up, Eigen::Vector3d::UnitZ(), 0, false, -1);  // back to park
  return tp;
}

}  // namespace post_test
