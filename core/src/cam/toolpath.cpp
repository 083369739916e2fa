// The toolpath of one nested sheet: which cut comes when, and every move of the tool tip.
//
// Per part (parts in nearest-neighbour order from the park position): dowel holes, holes, then the
// outer outline. Per outline: trim runs first — the stretches where an earlier pass of a convex
// multi-cut edge differs from the last pass — then the last pass, which frees what it encloses.
// A trim pass that differs everywhere would free the part by itself; it is cut open, leaving a
// bridge where its sliver is thinnest (or at the microjoints, when there are any), so the part
// stays in the sheet until its last pass.
#include "lamina/core/toolpath.hpp"

#include "cam/jet_compensation.hpp"
#include "cam/jet_corners.hpp"
#include "cam/rotary_rates.hpp"
#include "cam/toolpath_moves.hpp"
#include "cam/toolpath_ring.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace lamina {

const char* move_kind_name(MoveKind kind) {
  switch (kind) {
    case MoveKind::rapid: return "rapid";
    case MoveKind::pierce: return "pierce";
    case MoveKind::lead_in: return "lead_in";
    case MoveKind::cut: return "cut";
    case MoveKind::lead_out: return "lead_out";
  }
  return "?";
}

namespace {

using cam_detail::CompensatedPass;
using cam_detail::PathPoint;
using cam_detail::SheetFrame;

// Lines of two passes at one station closer than this are the same cut.
constexpr double kSameLineMm = 1e-6;


std::expected<void, Error> check_params(const ToolpathParams& p) {
  auto finite_at_least = [](double v, double lo) { return std::isfinite(v) && v >= lo; };
  if (!finite_at_least(p.kerf_mm, 0.0)) return std::unexpected(invalid_argument(fmt::format("kerf {} mm must be >= 0", p.kerf_mm)));
  if (!finite_at_least(p.lead_in_mm, 0.0)) return std::unexpected(invalid_argument(fmt::format("lead-in {} mm must be >= 0", p.lead_in_mm)));
  if (!finite_at_least(p.lead_out_mm, 0.0)) return std::unexpected(invalid_argument(fmt::format("lead-out {} mm must be >= 0", p.lead_out_mm)));
  if (!finite_at_least(p.pierce_dwell_s, 0.0))
    return std::unexpected(invalid_argument(fmt::format("pierce dwell {} s must be >= 0", p.pierce_dwell_s)));
  if (!(p.safe_z_mm > 0.0) || !std::isfinite(p.safe_z_mm))
    return std::unexpected(invalid_argument(fmt::format("safe height {} mm must be > 0", p.safe_z_mm)));
  if (!(p.rapid_mm_per_s > 0.0) || !std::isfinite(p.rapid_mm_per_s))
    return std::unexpected(invalid_argument(fmt::format("rapid rate {} mm/s must be > 0", p.rapid_mm_per_s)));
  if (!(p.max_turn_per_move_rad > 0.0) || !std::isfinite(p.max_turn_per_move_rad))
    return std::unexpected(invalid_argument(fmt::format("largest turn per move {} rad must be > 0", p.max_turn_per_move_rad)));
  if (p.microjoints < 0 || p.microjoints > 100)
    return std::unexpected(invalid_argument(fmt::format("microjoints {} must be 0 … 100", p.microjoints)));
  if (!(p.microjoint_width_mm > 0.0) || !std::isfinite(p.microjoint_width_mm))
    return std::unexpected(invalid_argument(fmt::format("microjoint width {} mm must be > 0", p.microjoint_width_mm)));
  if (!(p.corner_min_fraction > 0.0 && p.corner_min_fraction <= 1.0))
    return std::unexpected(invalid_argument(fmt::format("corner slow-down fraction {} must be in (0, 1]", p.corner_min_fraction)));
  const JetCorners& jc = p.jet_compensation.corners;
  if (!(std::isfinite(jc.error_mm) && jc.error_mm > 0.0))
    return std::unexpected(invalid_argument(fmt::format("corner error allowance {} mm must be > 0", jc.error_mm)));
  if (!(jc.min_fraction > 0.0 && jc.min_fraction <= 1.0))
    return std::unexpected(invalid_argument(fmt::format("jet corner slow-down floor {} must be in (0, 1]", jc.min_fraction)));
  if (!(p.a_max_rad_per_s > 0.0) || !(p.c_max_rad_per_s > 0.0))
    return std::unexpected(invalid_argument(fmt::format("rotary rates A {} and C {} rad/s must be > 0", p.a_max_rad_per_s, p.c_max_rad_per_s)));
  if (!finite_at_least(p.corner_angle_rad, 0.0))
    return std::unexpected(invalid_argument(fmt::format("corner angle {} rad must be >= 0", p.corner_angle_rad)));
  return {};
}

// What a contour is (ToolContour::frees / closed): a whole freeing ring, a run of a trim pass
// (where a multi-cut edge differs from the last pass), or a run between microjoints.
struct ContourShape {
  bool frees = false;
  bool closed = false;
};
constexpr ContourShape kFreeingRing{.frees = true, .closed = true};
constexpr ContourShape kTrimRun{.frees = false, .closed = false};
// Whether the runs between microjoints are of the pass that frees the part.
enum class Frees : bool { no, yes };

class SheetBuilder {
 public:
  SheetBuilder(const BevelPlan& plan, std::span<const Part> parts, const NestedSheet& sheet, const Material& material,
               const ToolpathParams& params)
      : plan_(plan), parts_(parts), sheet_(sheet), material_(material), p_(params) {}

  std::expected<SheetToolpath, Error> build() {
    if (auto ok = check_params(p_); !ok) return std::unexpected(ok.error());
    out_.sheet = sheet_.index;
    out_.thickness_mm = sheet_.thickness_mm;
    rapid_to({p_.park_mm.x(), p_.park_mm.y(), p_.safe_z_mm}, Eigen::Vector3d::UnitZ(), -1);
    auto order = cutting_order();
    if (!order) return std::unexpected(order.error());
    for (const int pi : *order) {
      if (auto ok = cut_placement(pi); !ok) return std::unexpected(ok.error());
    }
    rapid_to({p_.park_mm.x(), p_.park_mm.y(), p_.safe_z_mm}, Eigen::Vector3d::UnitZ(), -1);
    sum_time();
    return std::move(out_);
  }

 private:
  // Placements by nearest neighbour from the park position (footprint centroids), except that a
  // part nested in another part's hole (Placement::host) is cut completely before its host: the
  // host's hole cut frees the slug the child sits on.
  std::expected<std::vector<int>, Error> cutting_order() const {
    const std::size_t n = sheet_.placements.size();
    std::vector<Eigen::Vector2d> centre;
    std::vector<int> waiting(n, 0);  // children of each placement not cut yet
    for (const Placement& pl : sheet_.placements) {
      if (pl.part < 0 || static_cast<std::size_t>(pl.part) >= parts_.size())
        return std::unexpected(invalid_argument(fmt::format("sheet {}: a placement names part {} of {}", sheet_.index, pl.part,
                                                   parts_.size())));
      if (pl.host >= static_cast<int>(n) || pl.host < -1 || pl.host == static_cast<int>(centre.size()))
        return std::unexpected(invalid_argument(fmt::format("sheet {}: placement {} names host {} of {}", sheet_.index,
                                                   centre.size(), pl.host, n)));
      if (pl.host >= 0) ++waiting[static_cast<std::size_t>(pl.host)];
      const Part& part = parts_[static_cast<std::size_t>(pl.part)];
      Eigen::Vector2d c = Eigen::Vector2d::Zero();
      for (const auto& q : part.footprint_mm) c += q;
      c /= std::max<std::size_t>(1, part.footprint_mm.size());
      centre.push_back(place_point(pl, c));
    }
    std::vector<int> order;
    std::vector<bool> done(n, false);
    Eigen::Vector2d at = p_.park_mm;
    for (std::size_t k = 0; k < n; ++k) {
      std::size_t best = n;
      for (std::size_t i = 0; i < n; ++i)
        if (!done[i] && waiting[i] == 0 && (best == n || (centre[i] - at).norm() < (centre[best] - at).norm())) best = i;
      if (best == n)
        return std::unexpected(invalid_argument(fmt::format("sheet {}: the placements' hosts form a cycle", sheet_.index)));
      done[best] = true;
      order.push_back(static_cast<int>(best));
      if (const int h = sheet_.placements[best].host; h >= 0) --waiting[static_cast<std::size_t>(h)];
      at = centre[best];
    }
    return order;
  }

  std::expected<void, Error> cut_placement(int placement_index) {
    const Placement& pl = sheet_.placements[static_cast<std::size_t>(placement_index)];  // checked by cutting_order
    const Part& part = parts_[static_cast<std::size_t>(pl.part)];
    if (part.layer_slot < 0 || static_cast<std::size_t>(part.layer_slot) >= plan_.layers.size())
      return std::unexpected(invalid_argument(fmt::format("part {}: layer slot {} is not in the plan", part_label(part), part.layer_slot)));
    if (std::abs(part.thickness_mm - sheet_.thickness_mm) > 1e-9)
      return std::unexpected(invalid_argument(fmt::format("part {} is {} mm thick, sheet {} is {} mm", part_label(part),
                                                 part.thickness_mm, sheet_.index, sheet_.thickness_mm)));
    const LayerPlan& layer = plan_.layers[static_cast<std::size_t>(part.layer_slot)];
    SheetFrame frame;
    frame.rotation = Eigen::Rotation2Dd(pl.rotation_rad).toRotationMatrix();
    frame.offset_mm = pl.offset_mm;
    frame.z_top_mm = layer.z_top_mm();
    frame.thickness_mm = layer.thickness_mm;

    Target t{placement_index, pl.part, -1, 0, true};
    for (const Eigen::Vector2d& d : part.dowels_mm) {
      if (auto ok = cut_dowel(frame, t, d); !ok) return ok;
    }
    for (const int hi : part.holes) {
      t.outline = hi;
      t.is_hole = true;
      if (auto ok = cut_outline(frame, layer, t); !ok) return ok;
    }
    t.outline = part.outer;
    t.is_hole = false;
    return cut_outline(frame, layer, t);
  }

  struct Target {
    int placement, part, outline, pass;
    bool is_hole;
  };

  std::expected<void, Error> feed_points(std::vector<PathPoint>& pts, const std::string& where) {
    for (PathPoint& q : pts) {
      const double tilt = std::acos(std::clamp(q.axis.z(), -1.0, 1.0));
      auto f = cut_feed_mm_per_s(p_.jet, material_, p_.feed, sheet_.thickness_mm, tilt);
      if (!f) return std::unexpected(Error{f.error().code, where + ": " + f.error().message});
      q.feed_mm_per_s = *f;
    }
    return {};
  }

  // The jet's real kerf (JetCompensation): each line's separation speed at its tilt, the
  // material's kerf model, and the lines the tilt limit held back counted for the report.
  // Returns whether it compensated (off, or auto for an uncalibrated material, does not).
  std::expected<bool, Error> compensate_jet(std::vector<PathPoint>& pts, const std::string& where) {
    const JetCompensation& jc = p_.jet_compensation;
    if (jc.mode == JetCompensationMode::off) return false;
    const auto model = jc.kerf_by_material.find(material_.name);
    if (model == jc.kerf_by_material.end() && jc.mode == JetCompensationMode::automatic) return false;
    if (model == jc.kerf_by_material.end())
      return std::unexpected(invalid_argument(fmt::format("{}: no kerf calibration for '{}' (lamina calibrate coupon, then fit; docs/jet.md)",
                                                 where, material_.name)));
    std::vector<double> separation;
    for (const PathPoint& q : pts) {
      auto v = separation_feed_mm_per_s(p_.jet, material_, p_.feed, sheet_.thickness_mm, std::acos(std::clamp(q.axis.z(), -1.0, 1.0)));
      if (!v) return std::unexpected(Error{v.error().code, where + ": " + v.error().message});
      separation.push_back(*v);
    }
    const JetCompensationMode mode = jc.mode == JetCompensationMode::automatic ? JetCompensationMode::full : jc.mode;
    out_.jet_compensation = mode;
    // The corners' speeds first: the compensation reads each line's feed ratio, slow-down included.
    auto floored = cam_detail::jet_corner_speeds(pts, separation, {&model->second, sheet_.thickness_mm, jc.corners, p_.part_on_right});
    if (!floored) return std::unexpected(Error{floored.error().code, where + ", " + floored.error().message});
    out_.jet_corners_floored += *floored;
    const cam_detail::JetCompensationInput in{mode, &model->second, sheet_.thickness_mm, 0.5 * p_.kerf_mm, jc.tilt_max_rad, true};
    auto held = cam_detail::compensate_jet(pts, separation, in);
    if (!held) return std::unexpected(Error{held.error().code, where + ", " + held.error().message});
    out_.jet_tilt_limited += *held;
    return true;
  }

  // The jet compensation, then the rotary axes' rates (rotary_rates.hpp). Where those lower a
  // feed under compensation, it runs again from the planned lines at the lowered feeds, so its
  // kerf is the one at the feed the machine reaches, and the rates are held once more on the
  // lines it gives.
  std::expected<void, Error> compensate_within_rates(std::vector<PathPoint>& pts, const std::string& where) {
    const std::vector<PathPoint> planned = pts;
    const std::size_t tilt_limited = out_.jet_tilt_limited, floored = out_.jet_corners_floored;
    auto compensated = compensate_jet(pts, where);
    if (!compensated) return std::unexpected(compensated.error());
    const double a_rate = p_.a_max_rad_per_s, c_rate = p_.c_max_rad_per_s;
    if (cam_detail::limit_feeds_to_rotary_rates(pts, a_rate, c_rate) == 0 || !*compensated) return {};
    std::vector<PathPoint> again = planned;
    for (std::size_t i = 0; i < again.size(); ++i) again[i].feed_mm_per_s = pts[i].feed_mm_per_s;
    out_.jet_tilt_limited = tilt_limited, out_.jet_corners_floored = floored;
    if (auto ok = compensate_jet(again, where); !ok) return std::unexpected(ok.error());
    cam_detail::limit_feeds_to_rotary_rates(again, a_rate, c_rate);
    pts = std::move(again);
    return {};
  }

  // A trimming pass (every pass before the freeing one): only where its lines differ from the
  // freeing pass's, as runs with one shared line on either side; a pass that differs nearly all
  // round is opened at the microjoints, or at one bridge where it is thinnest.
  std::expected<void, Error> cut_trim_pass(const LayerOutline& outline, const std::vector<CompensatedPass>& passes,
                                           std::size_t pi, const std::vector<double>& tabs_u, double gap, Target t) {
    const CutPass& pass = outline.passes[pi];
    const CutPass& fin = outline.passes.back();
    const std::size_t n = pass.lines.size();
    std::vector<bool> differs(n);  // in cutting order
    std::vector<double> sliver(n);
    int count = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const std::size_t s = static_cast<std::size_t>(passes[pi].station_of[i]);
      const double d = std::max((pass.lines[s].top_mm - fin.lines[s].top_mm).norm(),
                                (pass.lines[s].bottom_mm - fin.lines[s].bottom_mm).norm());
      sliver[i] = d;
      differs[i] = d > kSameLineMm;
      count += differs[i];
    }
    if (count == 0) return {};  // the same cut as the freeing pass: nothing to trim
    count += join_short_gaps(passes[pi], differs);
    if (count >= static_cast<int>(n) - 1) {
      std::vector<double> bridges = tabs_u;
      if (bridges.empty())
        bridges.push_back(static_cast<double>(std::min_element(sliver.begin(), sliver.end()) - sliver.begin()));
      return cut_between(passes[pi], bridges, gap, t, Frees::no);
    }
    std::size_t start = 0;
    while (differs[start]) ++start;  // a line that does not differ (count < n)
    for (std::size_t k = 0; k < n;) {
      const std::size_t i = (start + k) % n;
      if (!differs[i]) {
        ++k;
        continue;
      }
      std::size_t len = 0;
      while (k + len < n && differs[(start + k + len) % n]) ++len;
      std::vector<PathPoint> run;
      for (std::size_t j = 0; j < len + 2; ++j) run.push_back(passes[pi].points[(i + n - 1 + j) % n]);
      emit_contour(std::move(run), passes[pi].points, t, kTrimRun);
      k += len;
    }
    return {};
  }

  std::expected<void, Error> cut_outline(const SheetFrame& frame, const LayerPlan& layer, Target t) {
    const LayerOutline& outline = layer.outlines[static_cast<std::size_t>(t.outline)];
    const std::string where = fmt::format("sheet {}, part {}, outline {}", sheet_.index,
                                          part_label(parts_[static_cast<std::size_t>(t.part)]), t.outline);
    if (outline.passes.empty() || outline.passes.back().lines.size() < 3 ||
        outline.stations.size() != outline.passes.back().lines.size())
      return std::unexpected(invalid_argument(where + ": no closed pass to cut"));
    const double h = 0.5 * p_.kerf_mm;
    const std::size_t last = outline.passes.size() - 1;
    std::vector<CompensatedPass> passes;
    for (const CutPass& pass : outline.passes) {
      if (pass.lines.size() != outline.stations.size())
        return std::unexpected(invalid_argument(where + ": passes with different station counts"));
      passes.push_back(cam_detail::compensate_pass(outline, pass, frame, p_.part_on_right, h));
      if (auto ok = feed_points(passes.back().points, where); !ok) return ok;
      cam_detail::mark_corners(passes.back().points, p_.corner_angle_rad, p_.corner_min_fraction);
      if (auto ok = compensate_within_rates(passes.back().points, where); !ok) return ok;
    }
    // Microjoints on the outer outline's freeing pass, as station parameters so every pass of the
    // outline leaves them at the same place.
    std::vector<double> tabs_u;
    const CompensatedPass& final_pass = passes[last];
    if (!t.is_hole && p_.microjoints > 0) {
      for (int k = 0; k < p_.microjoints; ++k) {
        const double s = (k + 0.5) * final_pass.length_mm / p_.microjoints;
        tabs_u.push_back(station_param(final_pass, s));
      }
    }
    const double gap = p_.microjoint_width_mm + p_.kerf_mm;  // path gap leaving the tab's width uncut

    for (std::size_t pi = 0; pi < last; ++pi) {
      t.pass = static_cast<int>(pi);
      if (auto ok = cut_trim_pass(outline, passes, pi, tabs_u, gap, t); !ok) return ok;
    }
    t.pass = static_cast<int>(last);
    if (tabs_u.empty()) {
      std::vector<PathPoint> ring = final_pass.points;
      ring.push_back(ring.front());
      cam_detail::append_overlap(ring);
      emit_contour(std::move(ring), final_pass.points, t, kFreeingRing);
      return {};
    }
    return cut_between(final_pass, tabs_u, gap, t, Frees::yes);
  }

  // Trim runs separated by a short stretch of lines shared with the freeing pass are cut as one:
  // a separate run costs a pierce dwell and two leads, so a shared stretch shorter than
  // dwell · feed + lead-in + lead-out is cheaper to cut through (it is cut again, on the same
  // surface, by the freeing pass). Faceted surfaces alternate convex and straight stations, and
  // without this a vase layer took a hundred pierces per pass. Returns how many lines it marked.
  int join_short_gaps(const CompensatedPass& pass, std::vector<bool>& differs) const {
    const std::size_t n = differs.size();
    std::size_t start = 0;
    while (start < n && differs[start]) ++start;
    if (start == n) return 0;
    // Walk from a differing line, so every gap found has a differing line on both sides.
    std::size_t first = start;
    while (!differs[first % n]) first = (first + 1) % n;
    int marked = 0;
    for (std::size_t k = 0; k < n;) {
      const std::size_t i = (first + k) % n;
      if (differs[i]) {
        ++k;
        continue;
      }
      std::size_t len = 0;
      double mm = 0.0, feed = std::numeric_limits<double>::infinity();
      while (len < n && !differs[(i + len) % n]) ++len;
      for (std::size_t j = 0; j <= len; ++j) {
        const PathPoint& a = pass.points[(i + n + j - 1) % n];
        const PathPoint& b = pass.points[(i + j) % n];
        mm += (b.tip - a.tip).norm();
        feed = std::min(feed, b.feed_mm_per_s);
      }
      if (len < n && mm < p_.pierce_dwell_s * feed + p_.lead_in_mm + p_.lead_out_mm) {
        for (std::size_t j = 0; j < len; ++j) differs[(i + j) % n] = true;
        marked += static_cast<int>(len);
      }
      k += len;
    }
    return marked;
  }

  // The station parameter (see cam_detail::arc_at) at arc length s of a pass.
  static double station_param(const CompensatedPass& pass, double s) {
    const std::size_t n = pass.points.size();
    for (std::size_t i = 0; i < n; ++i) {
      const double next = i + 1 < n ? pass.arc_mm[i + 1] : pass.length_mm;
      if (s <= next || i + 1 == n) {
        const double seg = next - pass.arc_mm[i];
        return static_cast<double>(i) + (seg > 1e-12 ? std::clamp((s - pass.arc_mm[i]) / seg, 0.0, 1.0) : 0.0);
      }
    }
    return 0.0;
  }

  // A closed pass cut as open runs between gaps centred at the station parameters `gaps_u`.
  std::expected<void, Error> cut_between(const CompensatedPass& pass, std::vector<double> gaps_u, double gap_mm,
                                         const Target& t, Frees frees) {
    if (gap_mm * static_cast<double>(gaps_u.size()) >= 0.9 * pass.length_mm)
      return std::unexpected(invalid_argument(fmt::format(
          "sheet {}, part {}: {} microjoint(s) of {} mm (kerf included) do not fit an outline {:.3f} mm long",
          sheet_.index, part_label(parts_[static_cast<std::size_t>(t.part)]), gaps_u.size(), gap_mm, pass.length_mm)));
    std::vector<double> centres;
    for (double u : gaps_u) centres.push_back(cam_detail::arc_at(pass, u));
    std::sort(centres.begin(), centres.end());
    const std::size_t k = centres.size();
    for (std::size_t j = 0; j < k; ++j) {
      const double s0 = centres[j] + 0.5 * gap_mm;
      double s1 = centres[(j + 1) % k] - 0.5 * gap_mm;
      if (j + 1 == k) s1 += pass.length_mm;
      if (s1 - s0 < 1e-6) continue;
      emit_contour(cam_detail::sub_path(pass, s0, s1), pass.points, t,
                   ContourShape{.frees = frees == Frees::yes, .closed = false});
      if (frees == Frees::yes) {
        // The uncut material: the gap minus the kerf on both sides.
        const double a = s1 + 0.5 * p_.kerf_mm, b = s1 + gap_mm - 0.5 * p_.kerf_mm;
        const auto piece = cam_detail::sub_path(pass, a, b);
        out_.microjoints.push_back({t.placement, piece.front().tip.head<2>(), piece.back().tip.head<2>()});
      }
    }
    return {};
  }

  std::expected<void, Error> cut_dowel(const SheetFrame& frame, Target t, const Eigen::Vector2d& centre_layer) {
    const double r = 0.5 * p_.dowel_diameter_mm;
    const double path_r = r - 0.5 * p_.kerf_mm;
    if (path_r <= 0.0)
      return std::unexpected(invalid_argument(fmt::format("dowel holes of {} mm are not wider than the kerf {} mm", 2 * r, p_.kerf_mm)));
    const Eigen::Vector3d c = frame.point({centre_layer.x(), centre_layer.y(), frame.z_top_mm});
    const int n = std::max(24, static_cast<int>(std::ceil(2 * std::numbers::pi * path_r / 0.5)));
    std::vector<PathPoint> ring;
    for (int i = 0; i < n; ++i) {
      // Holes run counter-clockwise when the part is on the jet's right.
      const double a = (p_.part_on_right ? 1.0 : -1.0) * 2 * std::numbers::pi * i / n;
      PathPoint q;
      q.tip = c + path_r * Eigen::Vector3d(std::cos(a), std::sin(a), 0.0);
      q.bottom = q.tip - sheet_.thickness_mm * Eigen::Vector3d::UnitZ();
      q.scrap = -Eigen::Vector2d(std::cos(a), std::sin(a));
      ring.push_back(q);
    }
    if (auto ok = feed_points(ring, fmt::format("sheet {}, dowel hole", sheet_.index)); !ok) return ok;
    cam_detail::mark_corners(ring, p_.corner_angle_rad, p_.corner_min_fraction);
    std::vector<PathPoint> closed = ring;
    closed.push_back(closed.front());
    t.outline = -1;
    t.pass = 0;
    t.is_hole = true;
    emit_contour(std::move(closed), ring, t, kFreeingRing);
    return {};
  }

  // Lead length from p along dir that stays in the scrap: half the way to the far side of the
  // contour's own ring (small holes: the pierce lands near the middle).
  static double fit_lead(double wanted, const std::vector<PathPoint>& ring, const Eigen::Vector2d& p,
                         const Eigen::Vector2d& dir) {
    return std::min(wanted, 0.5 * cam_detail::ray_to_ring(ring, p, dir));
  }

  // The jet is on for every move but a rapid (the pierce opens it, the lead-out closes the cut).
  void push(MoveKind kind, const Eigen::Vector3d& tip, const Eigen::Vector3d& axis, double feed, double duration,
            int contour, double dwell = 0.0) {
    ToolMove m;
    m.kind = kind;
    m.tip_mm = tip;
    m.axis = axis;
    m.feed_mm_per_s = feed;
    m.duration_s = duration;
    m.dwell_s = dwell;
    m.jet_on = kind != MoveKind::rapid;
    m.contour = contour;
    cam_detail::append_move(out_.moves, m, p_.max_turn_per_move_rad);
  }

  void rapid_to(const Eigen::Vector3d& tip, const Eigen::Vector3d& axis, int contour) {
    const Eigen::Vector3d from = out_.moves.empty() ? tip : out_.moves.back().tip_mm;
    push(MoveKind::rapid, tip, axis, 0.0, (tip - from).norm() / p_.rapid_mm_per_s, contour);
  }

  // One contour: rapid over the pierce point, down, pierce, lead-in, the cut, lead-out, up.
  void emit_contour(std::vector<PathPoint> pts, const std::vector<PathPoint>& ring, const Target& t,
                    ContourShape shape) {
    const int id = static_cast<int>(out_.contours.size());
    ToolContour c;
    c.placement = t.placement;
    c.part = t.part;
    c.label = part_label(parts_[static_cast<std::size_t>(t.part)]);
    c.outline = t.outline;
    c.pass = t.pass;
    c.is_hole = t.is_hole;
    c.frees = shape.frees;
    c.closed = shape.closed;
    c.first_move = out_.moves.size();
    const PathPoint& first = pts.front();
    const PathPoint& end = pts.back();
    const double t_mm = sheet_.thickness_mm;
    const Eigen::Vector3d down = t_mm * Eigen::Vector3d::UnitZ();

    // The pierce is vertical: it must clear the part on both faces, so the lead is measured from
    // whichever end of the first line reaches further into the scrap (a wall that widens
    // downwards puts the part's bottom edge under a pierce 3 mm off the top contour).
    const double reach_in = std::max(0.0, (first.bottom.head<2>() - first.tip.head<2>()).dot(first.scrap));
    const double lead_in = fit_lead(p_.lead_in_mm + reach_in, ring, first.tip.head<2>(), first.scrap);
    const Eigen::Vector2d pierce2 = first.tip.head<2>() + lead_in * first.scrap;
    const Eigen::Vector3d pierce(pierce2.x(), pierce2.y(), 0.0);
    c.pierce_mm = pierce2;
    rapid_to({pierce.x(), pierce.y(), p_.safe_z_mm}, Eigen::Vector3d::UnitZ(), id);
    rapid_to(pierce, Eigen::Vector3d::UnitZ(), id);
    push(MoveKind::pierce, pierce, Eigen::Vector3d::UnitZ(), 0.0, p_.pierce_dwell_s, id, p_.pierce_dwell_s);
    // Lead-in: the head turns from vertical (the pierce) to the first line's axis on the way.
    const double f_in = first.feed_mm_per_s * first.corner_factor;
    push(MoveKind::lead_in, first.tip, first.axis, f_in, cam_detail::jet_travel_s(pierce, pierce - down, first.tip, first.bottom, f_in), id);
    for (std::size_t k = 1; k < pts.size(); ++k) {
      const PathPoint& a = pts[k - 1];
      const PathPoint& b = pts[k];
      PathPoint from = a;
      for (const cam_detail::FeedPiece& piece : cam_detail::feed_pieces(a, b)) {
        const double f = std::min(a.feed_mm_per_s, b.feed_mm_per_s) * piece.factor;
        const double dur = cam_detail::jet_travel_s(from.tip, from.bottom, piece.to.tip, piece.to.bottom, f);
        if (dur <= 0.0) continue;  // a repeated line
        push(MoveKind::cut, piece.to.tip, piece.to.axis, f, dur, id);
        out_.moves.back().tilt_limited = b.tilt_limited;
        from = piece.to;
      }
    }
    const double lead_out = fit_lead(p_.lead_out_mm, ring, end.tip.head<2>(), end.scrap);
    const Eigen::Vector2d out2 = end.tip.head<2>() + lead_out * end.scrap;
    const Eigen::Vector3d out(out2.x(), out2.y(), 0.0);
    const Eigen::Vector3d out_bottom = out - (t_mm / end.axis.z()) * end.axis;
    const double f_out = end.feed_mm_per_s * end.corner_factor;
    if (lead_out > 0.0)
      push(MoveKind::lead_out, out, end.axis, f_out, cam_detail::jet_travel_s(end.tip, end.bottom, out, out_bottom, f_out), id);
    rapid_to({out.x(), out.y(), p_.safe_z_mm}, end.axis, id);
    c.end_move = out_.moves.size();
    out_.contours.push_back(c);
  }

  void sum_time() { out_.time = cut_time(out_.moves); }

  const BevelPlan& plan_;
  std::span<const Part> parts_;
  const NestedSheet& sheet_;
  const Material& material_;
  const ToolpathParams& p_;
  SheetToolpath out_;
};

}  // namespace

const ChoiceTable<JetCompensationMode>& jet_compensation_modes() {
  static constexpr Choice<JetCompensationMode> rows[] = {
      {JetCompensationMode::automatic, "auto", "full where the material has a kerf calibration, off where not"},
      {JetCompensationMode::off, "off", "the jet's kerf as one width along the axis (programs as before)"},
      {JetCompensationMode::taper, "taper", "top and bottom offset by the kerf model's own widths"},
      {JetCompensationMode::full, "full", "taper, and the exit aimed ahead by the trail-back"}};
  static constexpr ChoiceTable<JetCompensationMode> table{"jet compensation", rows};
  return table;
}

const ChoiceTable<InsideCorners>& inside_corner_strategies() {
  static constexpr Choice<InsideCorners> rows[] = {
      {InsideCorners::slow, "slow", "inside corners slowed like outside ones, to the corner allowance"},
      {InsideCorners::keep, "keep", "inside corners at the feed: the bottom keeps a fillet of material, no time lost"}};
  static constexpr ChoiceTable<InsideCorners> table{"inside corners", rows};
  return table;
}

const char* inside_corners_name(InsideCorners s) {
  for (const auto& row : inside_corner_strategies().rows())
    if (row.value == s) return row.name.data();
  return "slow";
}

const char* jet_compensation_name(JetCompensationMode mode) {
  for (const auto& row : jet_compensation_modes().rows())
    if (row.value == mode) return row.name.data();
  return "off";
}

CutTime cut_time(std::span<const ToolMove> moves) {
  CutTime tm;
  Eigen::Vector3d at = moves.empty() ? Eigen::Vector3d::Zero() : moves.front().tip_mm;
  for (const ToolMove& m : moves) {
    const double d = (m.tip_mm - at).norm();
    switch (m.kind) {
      case MoveKind::rapid: tm.rapid_s += m.duration_s, tm.rapid_length_mm += d; break;
      case MoveKind::pierce: tm.pierce_s += m.duration_s, ++tm.pierces; break;
      default: tm.cutting_s += m.duration_s, tm.cut_length_mm += d; break;
    }
    at = m.tip_mm;
  }
  tm.total_s = tm.cutting_s + tm.rapid_s + tm.pierce_s;
  return tm;
}

std::expected<SheetToolpath, Error> plan_sheet_toolpath(const BevelPlan& plan, std::span<const Part> parts,
                                                        const NestedSheet& sheet, const Material& material,
                                                        const ToolpathParams& params) {
  return SheetBuilder(plan, parts, sheet, material, params).build();
}

}  // namespace lamina
