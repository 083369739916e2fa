#pragma once
// Private to the toolpath: a pass as the jet will follow it — kerf-compensated, in the sheet frame,
// in cutting order — and pieces of it cut out by arc length (runs between microjoints, trim runs).
#include "lamina/core/bevel.hpp"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <algorithm>
#include <limits>
#include <vector>

namespace lamina::cam_detail {

// Layer (build frame) → sheet frame: rotate about +Z, shift, and put the layer's top face at z = 0.
struct SheetFrame {
  Eigen::Matrix2d rotation = Eigen::Matrix2d::Identity();
  Eigen::Vector2d offset_mm = Eigen::Vector2d::Zero();
  double z_top_mm = 0.0;
  double thickness_mm = 0.0;

  Eigen::Vector3d point(const Eigen::Vector3d& p) const {
    const Eigen::Vector2d xy = rotation * p.head<2>() + offset_mm;
    return {xy.x(), xy.y(), p.z() - z_top_mm};
  }
  Eigen::Vector3d direction(const Eigen::Vector3d& v) const {
    const Eigen::Vector2d xy = rotation * v.head<2>();
    return {xy.x(), xy.y(), v.z()};
  }
};

// One jet line of a compensated pass.
struct PathPoint {
  Eigen::Vector3d tip = Eigen::Vector3d::Zero();     // on the top face (z = 0)
  Eigen::Vector3d bottom = Eigen::Vector3d::Zero();  // on the bottom face (z = −thickness)
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();   // unit, tip → nozzle
  Eigen::Vector2d scrap = Eigen::Vector2d::Zero();   // unit, horizontal, away from the part
  double feed_mm_per_s = 0.0;                        // the feed model's at this line's tilt
  double corner_factor = 1.0;                        // slow-down at a sharp corner of the top path
  bool tilt_limited = false;                         // jet compensation held at the head's tilt limit
  double trail_back_mm = 0.0;                        // the jet's trail-back here (jet compensation; 0 without it)
  // The jet's lag at the full feed would leave more than the corner allowance here (a corner, a
  // tight curve: jet_corners.hpp); only there does full compensation aim the exit ahead.
  bool lag_beyond_allowance = false;
  // How far along the path, either side, corner_factor holds: infinite (the angle heuristic) is
  // the whole of both moves that meet here; the trail-back's corner speeds hold it for the lag.
  double slow_zone_mm = std::numeric_limits<double>::infinity();
};

// How long the jet takes from one line to the next: the longer of the top's and the bottom's
// travel at the feed (a move that only turns the head about its tip still moves its bottom).
inline double jet_travel_s(const Eigen::Vector3d& top0, const Eigen::Vector3d& bottom0, const Eigen::Vector3d& top1,
                           const Eigen::Vector3d& bottom1, double feed_mm_per_s) {
  return std::max((top1 - top0).norm(), (bottom1 - bottom0).norm()) / feed_mm_per_s;
}

// The lines of pass `pass` of `outline`, in cutting order (reversed when `reverse`), each moved by
// half the kerf towards the scrap along the ruled surface's normal — the normals of the two faces
// meeting at a line joined as a mitre, so both faces keep their distance — then re-intersected
// with the top face. station_of[i] is the station index of point i.
struct CompensatedPass {
  std::vector<PathPoint> points;
  std::vector<int> station_of;
  std::vector<double> arc_mm;  // arc length of the tip path at each point; back at point 0: length_mm
  double length_mm = 0.0;
};
CompensatedPass compensate_pass(const LayerOutline& outline, const CutPass& pass, const SheetFrame& frame,
                                bool reverse, double half_kerf_mm);

// Corner slow-down factors on a closed path of points (in place): a turn of the tip path (in the top
// face) sharper than corner_angle_rad gets max(min_fraction, cos(turn / 2)).
void mark_corners(std::vector<PathPoint>& points, double corner_angle_rad, double min_fraction);

// The move from a to b in pieces of one feed factor each: a's corner_factor within a's
// slow_zone_mm of a, b's within b's of b, the slower where both hold, 1 where neither. The last
// piece ends at b itself; with infinite zones (the angle heuristic) it is one piece at the
// smaller factor, as before.
struct FeedPiece {
  PathPoint to;
  double factor = 1.0;
};
std::vector<FeedPiece> feed_pieces(const PathPoint& a, const PathPoint& b);

// Arc length on the closed tip path at a station parameter u ∈ [0, n): point floor(u), then the
// fraction of the way to the next point.
double arc_at(const CompensatedPass& pass, double u);

// The piece of the closed path from arc length s0 to s1 (s0 < s1 ≤ s0 + length; s may exceed the
// length: the path wraps), with interpolated end points.
std::vector<PathPoint> sub_path(const CompensatedPass& pass, double s0_mm, double s1_mm);

// Distance from `from` along the unit direction `dir` to the first crossing of the closed ring of
// tip points (ignoring crossings closer than 1 µm); infinity when there is none.
double ray_to_ring(const std::vector<PathPoint>& ring, const Eigen::Vector2d& from, const Eigen::Vector2d& dir);

}  // namespace lamina::cam_detail
