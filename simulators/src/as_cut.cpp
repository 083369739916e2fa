#include "as_cut.hpp"

#include <fmt/format.h>
#include <polyclipping/clipper.hpp>

#include <algorithm>
#include <cmath>
#include <map>

#include "program_run.hpp"

namespace lamina::sim {
namespace {

constexpr double kScale = 1e4;  // Clipper units per mm: 0.1 µm
using Point2 = std::array<double, 2>;

// The kerf at one depth along one step of the tip: from a to b, this half width across the travel.
struct KerfStep {
  Point2 a, b;
  double half_width_mm = 0.0;
};

// Where the undeflected jet crosses `depth_mm` below the top face, and how wide the kerf is there
// across the travel.
struct JetAtDepth {
  Point2 centre{};
  double half_width_mm = 0.0;  // 0: the jet does not reach this depth
};

JetAtDepth jet_at_depth(const JetPose& pose, const CutWall& wall, double depth_mm, const Point2& travel) {
  JetAtDepth out;
  const double axis_z = pose.axis[2];
  // Down the jet from the tip (on the top face, z = 0) to z = −depth.
  const double along = (pose.tip_mm[2] + depth_mm) / axis_z;
  out.centre = {pose.tip_mm[0] - pose.axis[0] * along, pose.tip_mm[1] - pose.axis[1] * along};
  const double radius = 0.5 * wall.top_width_mm - along * wall.wall_lean_tan;
  if (!(radius > 0.0)) return out;
  // A tilted jet's cross-section is an ellipse, longer by 1 / cos(tilt) along the tilt: its
  // extent across the travel grows with the part of the tilt that lies across it.
  const double axis_xy = std::hypot(pose.axis[0], pose.axis[1]);
  double across_tilt = 0.0;
  if (axis_xy > 1e-12) across_tilt = (-travel[1] * pose.axis[0] + travel[0] * pose.axis[1]) / axis_xy;
  const double tan_tilt = axis_xy / axis_z;
  out.half_width_mm = radius * std::sqrt(1.0 + across_tilt * across_tilt * tan_tilt * tan_tilt);
  return out;
}

// The jet below the top face is dragged behind the nozzle: at each depth its centre follows the
// undeflected point with a lag in distance travelled, e' = (p − e) / L, L the trail-back at that
// depth. On a straight cut it settles L behind, as the physics' trail-back says; through a corner
// it cuts across, inside the turn: the corner error a real jet leaves.
Point2 dragged(const Point2& exit, const Point2& undeflected, double travelled_mm, double lag_mm) {
  if (!(lag_mm > 1e-9)) return undeflected;
  const double f = 1.0 - std::exp(-travelled_mm / lag_mm);
  return {exit[0] + (undeflected[0] - exit[0]) * f, exit[1] + (undeflected[1] - exit[1]) * f};
}

AxisValues lerp(const AxisValues& a, const AxisValues& b, double f) {
  AxisValues out{};
  for (std::size_t i = 0; i < a.size(); ++i) out[i] = a[i] + (b[i] - a[i]) * f;
  return out;
}

class KerfSweep {
 public:
  KerfSweep(const HeadGeometry& head, const JetPhysics& jet, const AsCutParams& params)
      : head_(head), jet_(jet), params_(params), steps_(static_cast<std::size_t>(params.sections)),
        exits_(static_cast<std::size_t>(params.sections)) {
    for (int k = 0; k < params.sections; ++k) depths_.push_back((k + 0.5) * params.sheet_thickness_mm / params.sections);
  }

  void add(const ExecutedBlock& block);
  std::vector<AsCutSection> sections() const;
  std::size_t cut_blocks() const { return cut_blocks_; }

 private:
  AsCutSection section(std::size_t k) const;

  HeadGeometry head_;
  JetPhysics jet_;
  AsCutParams params_;
  std::vector<double> depths_;
  std::vector<std::vector<KerfStep>> steps_;  // per depth, in cutting order
  std::vector<Point2> exits_;                 // per depth, where the jet is while it cuts
  bool cutting_ = false;                      // the jet has been on since the exits were set
  std::size_t cut_blocks_ = 0;
};

void KerfSweep::add(const ExecutedBlock& block) {
  if (!block.jet) cutting_ = false;  // off: the next cut starts with a straight jet
  if (!block.jet || !(block.t_end_s > block.t_start_s)) return;
  const JetPose from = jet_pose(block.start, head_), to = jet_pose(block.end, head_);
  const double travel_mm = std::hypot(to.tip_mm[0] - from.tip_mm[0], to.tip_mm[1] - from.tip_mm[1], to.tip_mm[2] - from.tip_mm[2]);
  if (travel_mm < 1e-6) return;  // a pierce: its hole lies in the scrap, at the lead-in's start
  ++cut_blocks_;
  const double feed_mm_per_s = travel_mm / (block.t_end_s - block.t_start_s);
  const double t = params_.sheet_thickness_mm;
  const auto n = static_cast<std::size_t>(std::max(1.0, std::ceil(travel_mm / params_.segment_mm)));
  JetPose a = from;
  for (std::size_t i = 1; i <= n; ++i) {
    const JetPose b = i == n ? to : jet_pose(lerp(block.start, block.end, static_cast<double>(i) / static_cast<double>(n)), head_);
    const double dx = b.tip_mm[0] - a.tip_mm[0], dy = b.tip_mm[1] - a.tip_mm[1], len = std::hypot(dx, dy);
    if (len > 1e-9 && a.axis[2] > 0.05 && b.axis[2] > 0.05) {
      const Point2 travel{dx / len, dy / len};
      const CutWall wall_a = cut_wall(jet_, t / a.axis[2], feed_mm_per_s), wall_b = cut_wall(jet_, t / b.axis[2], feed_mm_per_s);
      for (std::size_t k = 0; k < depths_.size(); ++k) {
        const JetAtDepth ja = jet_at_depth(a, wall_a, depths_[k], travel), jb = jet_at_depth(b, wall_b, depths_[k], travel);
        const Point2 from_exit = cutting_ ? exits_[k] : ja.centre;
        exits_[k] = dragged(from_exit, jb.centre, len, wall_b.trail_back_mm * depths_[k] / t);
        const double half = 0.5 * (ja.half_width_mm + jb.half_width_mm);
        if (half > 0.0) steps_[k].push_back({from_exit, exits_[k], half});
      }
      cutting_ = true;
    }
    a = b;
  }
}

ClipperLib::IntPoint to_int(const Point2& p) {
  return {static_cast<ClipperLib::cInt>(std::llround(p[0] * kScale)), static_cast<ClipperLib::cInt>(std::llround(p[1] * kScale))};
}

Ring to_ring(const ClipperLib::Path& path) {
  Ring ring;
  ring.reserve(path.size());
  for (const auto& p : path) ring.push_back({static_cast<double>(p.X) / kScale, static_cast<double>(p.Y) / kScale});
  return ring;
}

// Every region the kerfs enclose, but the one outside them all: pieces inside holes of pieces
// (a part in a part's hole, the slug of a hole) are found by walking down the tree.
void collect_pieces(const ClipperLib::PolyNode& outer, bool is_frame, std::vector<AsCutPiece>& out) {
  if (!is_frame) {
    AsCutPiece piece;
    piece.rings.push_back(to_ring(outer.Contour));
    for (const ClipperLib::PolyNode* hole : outer.Childs) piece.rings.push_back(to_ring(hole->Contour));
    out.push_back(std::move(piece));
  }
  for (const ClipperLib::PolyNode* hole : outer.Childs)
    for (const ClipperLib::PolyNode* inner : hole->Childs) collect_pieces(*inner, false, out);
}

AsCutSection KerfSweep::section(std::size_t k) const {
  AsCutSection out;
  out.depth_mm = depths_[k];
  // Runs of connected steps of one width, swept at once per width.
  std::map<long long, ClipperLib::Paths> runs;
  long long run_key = -1;
  for (const KerfStep& s : steps_[k]) {
    const long long key = std::max(1LL, std::llround(s.half_width_mm / params_.width_step_mm));
    const ClipperLib::IntPoint a = to_int(s.a), b = to_int(s.b);
    ClipperLib::Paths& bucket = runs[key];
    if (key != run_key || bucket.empty() || bucket.back().back() != a) bucket.push_back({a});
    if (b != bucket.back().back()) bucket.back().push_back(b);
    run_key = key;
  }
  ClipperLib::Paths kerf;
  for (auto& [key, paths] : runs) {
    ClipperLib::ClipperOffset sweep(2.0, 0.001 * kScale);
    for (auto& p : paths)
      if (p.size() == 1) p.push_back(p.front());  // a step shorter than the grid: a round dot
    sweep.AddPaths(paths, ClipperLib::jtRound, ClipperLib::etOpenRound);
    ClipperLib::Paths swept;
    sweep.Execute(swept, static_cast<double>(key) * params_.width_step_mm * kScale);
    kerf.insert(kerf.end(), swept.begin(), swept.end());
  }
  if (kerf.empty()) return out;
  ClipperLib::Clipper join;
  join.AddPaths(kerf, ClipperLib::ptSubject, true);
  const ClipperLib::IntRect box = join.GetBounds();
  const auto margin = static_cast<ClipperLib::cInt>(5.0 * kScale);
  const ClipperLib::Path frame{{box.left - margin, box.bottom + margin}, {box.right + margin, box.bottom + margin},
                               {box.right + margin, box.top - margin}, {box.left - margin, box.top - margin}};
  ClipperLib::Clipper cut;
  cut.AddPath(frame, ClipperLib::ptSubject, true);
  cut.AddPaths(kerf, ClipperLib::ptClip, true);
  ClipperLib::PolyTree tree;
  cut.Execute(ClipperLib::ctDifference, tree, ClipperLib::pftNonZero, ClipperLib::pftNonZero);
  // The frame is the one outer ring that reaches the frame's corner.
  for (const ClipperLib::PolyNode* outer : tree.Childs) {
    const bool is_frame = std::any_of(outer->Contour.begin(), outer->Contour.end(), [&](const ClipperLib::IntPoint& p) {
      return p.X == box.left - margin;
    });
    collect_pieces(*outer, is_frame, out.pieces);
  }
  return out;
}

std::vector<AsCutSection> KerfSweep::sections() const {
  std::vector<AsCutSection> out;
  for (std::size_t k = 0; k < depths_.size(); ++k) out.push_back(section(k));
  return out;
}

nlohmann::json ring_json(const Ring& ring) {
  auto flat = nlohmann::json::array();
  for (const auto& p : ring) {
    flat.push_back(std::round(p[0] * 1e4) / 1e4);
    flat.push_back(std::round(p[1] * 1e4) / 1e4);
  }
  return flat;
}

}  // namespace

std::expected<AsCut, std::string> cut_program(std::string_view program, MachineConfig machine,
                                              const HeadGeometry& head, const JetPhysics& jet,
                                              const AsCutParams& params) {
  if (!(params.sheet_thickness_mm > 0.0) || params.sections < 1 || params.sections > 1000 || !(params.segment_mm > 0.0) ||
      !(params.width_step_mm > 0.0))
    return std::unexpected(fmt::format("as-cut: a sheet thickness > 0, 1-1000 sections and steps > 0 (got {} mm, {}, {} mm, {} mm)",
                                       params.sheet_thickness_mm, params.sections, params.segment_mm, params.width_step_mm));
  KerfSweep sweep(head, jet, params);
  ProgramCallbacks callbacks;
  callbacks.on_block = [&](const ExecutedBlock& b) { sweep.add(b); };
  if (auto ran = run_program(program, std::move(machine), callbacks); !ran) return std::unexpected(ran.error());
  AsCut out;
  out.sheet_thickness_mm = params.sheet_thickness_mm;
  out.cut_blocks = sweep.cut_blocks();
  out.sections = sweep.sections();
  return out;
}

nlohmann::json as_cut_json(const AsCut& cut, std::string_view program_name, std::string_view program) {
  auto sections = nlohmann::json::array();
  for (const AsCutSection& s : cut.sections) {
    auto pieces = nlohmann::json::array();
    for (const AsCutPiece& piece : s.pieces) {
      auto rings = nlohmann::json::array();
      for (const Ring& r : piece.rings) rings.push_back(ring_json(r));
      pieces.push_back(std::move(rings));
    }
    sections.push_back({{"depth_mm", s.depth_mm}, {"pieces", std::move(pieces)}});
  }
  return {{"format", "lamina-sim as-cut 1"},
          {"program", program_name},
          {"program_fnv1a64", program_fingerprint(program)},
          {"sheet_thickness_mm", cut.sheet_thickness_mm},
          {"cut_blocks", cut.cut_blocks},
          {"sections", std::move(sections)}};
}

}  // namespace lamina::sim
