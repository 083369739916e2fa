// The bevel plan (paper 3-4, 3-5): per layer, the outline every sub-slice fits in (the vertical
// "outside" edge), stations along it, each station's profile read on every sub-slice along its
// normal, the cut lines fitted to that profile, and passes assembled from the lines.
#include "lamina/core/bevel.hpp"

#include "clipper_bridge.hpp"
#include "lamina/core/section_lines.hpp"
#include "lamina/core/slice.hpp"

#include <Eigen/Geometry>
#include <fmt/format.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

namespace lamina {

std::vector<double> sub_slice_heights(double z_bottom_mm, double thickness_mm, double sub_slice_mm) {
  std::vector<double> zs;
  if (!(thickness_mm > 0.0) || !(sub_slice_mm > 0.0)) return zs;
  const double nudge = std::min(1e-3, 0.01 * thickness_mm);
  const int intervals = std::max(1, static_cast<int>(std::ceil(thickness_mm / sub_slice_mm - 1e-9)));
  zs.reserve(static_cast<std::size_t>(intervals) + 1);
  for (int i = 0; i <= intervals; ++i) {
    double z = z_bottom_mm + thickness_mm * i / intervals;
    if (i == 0) z += nudge;
    if (i == intervals) z -= nudge;
    zs.push_back(z);
  }
  return zs;
}

namespace {

struct OutlineRing {
  Polygon2 points;
  bool is_hole = false;
  int parent = -1;
};

// The union of every sub-slice's material: what a vertical outside cut would keep. Outer rings
// CCW, holes CW, holes linked to their outer ring.
std::vector<OutlineRing> layer_outline_rings(const std::vector<const Slice*>& sub_slices) {
  ClipperLib::Paths all;
  for (const Slice* s : sub_slices) {
    for (const Loop& l : s->loops) all.push_back(detail::to_clipper(l.points));
  }
  ClipperLib::Clipper clipper;
  clipper.AddPaths(all, ClipperLib::ptSubject, true);
  ClipperLib::PolyTree tree;
  clipper.Execute(ClipperLib::ctUnion, tree, ClipperLib::pftPositive, ClipperLib::pftPositive);
  std::vector<OutlineRing> rings;
  // Drop vertices closer than 0.1 µm and collinear runs: unions of near-identical sub-slices
  // leave such crumbs, and every vertex becomes a station.
  auto add = [&](const ClipperLib::PolyNode& node, int parent) {
    ClipperLib::Path path = node.Contour;
    ClipperLib::CleanPolygon(path, 100.0);
    if (path.size() < 3) return -1;
    OutlineRing r;
    r.points = detail::from_clipper(path);
    r.is_hole = node.IsHole();
    r.parent = parent;
    if (std::abs(signed_area_mm2(r.points)) < 1e-8) return -1;
    rings.push_back(std::move(r));
    return static_cast<int>(rings.size()) - 1;
  };
  std::vector<std::pair<const ClipperLib::PolyNode*, int>> stack;
  for (const ClipperLib::PolyNode* child : tree.Childs) stack.emplace_back(child, -1);
  while (!stack.empty()) {
    auto [node, parent] = stack.back();
    stack.pop_back();
    const int self = add(*node, node->IsHole() ? parent : -1);
    // Holes belong to the outer above them; islands inside a hole are new outers.
    for (const ClipperLib::PolyNode* child : node->Childs) stack.emplace_back(child, node->IsHole() ? -1 : self);
  }
  return rings;
}

struct StationSeed {
  Eigen::Vector2d point, normal;
};

// Stations: every ring vertex (normal: bisector of its edges' normals) and extra points on edges
// longer than the spacing (normal: the edge's). Normals point out of the material for outer and
// hole rings alike (material is on the left of the ring's direction).
std::vector<StationSeed> station_seeds(const Polygon2& ring, double spacing_mm) {
  const std::size_t n = ring.size();
  std::vector<Eigen::Vector2d> edge_normal(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector2d e = ring[(i + 1) % n] - ring[i];
    const double len = e.norm();
    edge_normal[i] = len > 0 ? Eigen::Vector2d(e.y() / len, -e.x() / len) : Eigen::Vector2d::Zero();
  }
  std::vector<StationSeed> seeds;
  seeds.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    Eigen::Vector2d nrm = edge_normal[(i + n - 1) % n] + edge_normal[i];
    nrm = nrm.norm() > 1e-12 ? nrm.normalized() : edge_normal[i];
    seeds.push_back({ring[i], nrm});
    const Eigen::Vector2d a = ring[i], b = ring[(i + 1) % n];
    const double len = (b - a).norm();
    const int extra = spacing_mm > 0 ? static_cast<int>(std::ceil(len / spacing_mm)) - 1 : 0;
    for (int k = 1; k <= extra; ++k) {
      const double t = static_cast<double>(k) / (extra + 1);
      seeds.push_back({a + t * (b - a), edge_normal[i]});
    }
  }
  return seeds;
}

double wrap_near(double angle, double reference) {
  // The representative of angle (mod 2π) closest to reference: C never jumps by a turn.
  const double two_pi = 2.0 * M_PI;
  return angle + two_pi * std::round((reference - angle) / two_pi);
}

CutLine make_line(const CutStation& st, const CutLine1D& cut, double zb, double zt, const Eigen::Vector3d& paper_v) {
  CutLine line;
  const Eigen::Vector2d top = st.base_mm + cut.u_top_mm * st.normal;
  const Eigen::Vector2d bottom = st.base_mm + cut.u_bottom_mm * st.normal;
  line.top_mm = Eigen::Vector3d(top.x(), top.y(), zt);
  line.bottom_mm = Eigen::Vector3d(bottom.x(), bottom.y(), zb);
  line.tool_axis = (line.top_mm - line.bottom_mm).normalized();
  const double xy = std::hypot(line.tool_axis.x(), line.tool_axis.y());
  line.tilt_rad = std::atan2(xy, line.tool_axis.z());
  line.c_rad = std::atan2(line.tool_axis.y(), line.tool_axis.x());
  line.paper_v = paper_v;
  if (paper_v.squaredNorm() > 0) {
    const double vxy = std::hypot(paper_v.x(), paper_v.y());
    line.paper_a_deg = 180.0 - std::atan2(vxy, paper_v.z()) * 180.0 / M_PI;
    line.paper_c_deg = std::atan2(paper_v.y(), paper_v.x()) * 180.0 / M_PI;
  }
  return line;
}

// Make C continuous along a closed pass: unwrap against the previous line, and hold it where the
// axis is vertical (C is undefined there; holding it avoids a needless head swing).
void unwind_c(CutPass& pass) {
  constexpr double kVertical = 1e-6;
  double reference = 0.0;
  for (const auto& l : pass.lines) {
    if (l.tilt_rad > kVertical) { reference = l.c_rad; break; }
  }
  for (auto& l : pass.lines) {
    if (l.tilt_rad <= kVertical) {
      l.c_rad = reference;
    } else {
      l.c_rad = wrap_near(l.c_rad, reference);
      reference = l.c_rad;
    }
  }
}

LayerPlan plan_layer(const Mesh& mesh, const LayerSpan& span, int index, const std::vector<double>& zs,
                     const std::vector<const Slice*>& sub_slices, const BevelParams& params) {
  LayerPlan plan;
  plan.index = index;
  plan.z_bottom_mm = span.z_bottom_mm;
  plan.thickness_mm = span.thickness_mm;
  plan.sub_slice_z_mm = zs;
  const double zb = span.z_bottom_mm, zt = span.z_top_mm();

  std::vector<SectionLines> lines;
  lines.reserve(sub_slices.size());
  for (const Slice* s : sub_slices) lines.emplace_back(mesh, *s);

  // How far in a sample may lie and still be this station's surface: what a line at the tilt
  // limit reaches across the layer, plus a sub-slice of slack. Further in, the surface has
  // turned (nearly) horizontal: the sample counts as absent and the profile gets a ledge.
  const double tan_max = std::tan(std::min(params.fit.tilt_max_rad, 1.5));
  const double reach = span.thickness_mm * std::max(tan_max, 1.0) + 2.0 * params.sub_slice_mm;
  // The outline went through Clipper (1 nm grid) and was cleaned at 0.1 µm: a sub-slice that
  // defines it may sit that much outside.
  constexpr double kOnOutline = 1e-3;

  std::vector<ProfileSample> samples(zs.size());
  for (const OutlineRing& ring : layer_outline_rings(sub_slices)) {
    LayerOutline outline;
    outline.is_hole = ring.is_hole;
    outline.parent = ring.parent;
    const auto seeds = station_seeds(ring.points, params.station_spacing_mm);
    std::vector<ProfileFit> fits;
    std::vector<Eigen::Vector3d> paper_vs;
    fits.reserve(seeds.size());
    for (const StationSeed& seed : seeds) {
      CutStation st;
      st.base_mm = seed.point;
      st.normal = seed.normal;
      Eigen::Vector3d top_normal = Eigen::Vector3d::Zero();
      for (std::size_t j = 0; j < zs.size(); ++j) {
        ProfileSample& s = samples[j];
        s.z_mm = zs[j];
        const auto hit = lines[j].exit_crossing(seed.point, seed.normal, -reach, kOnOutline, CrossingPick::largest);
        s.present = hit.has_value();
        if (hit) {
          s.u_mm = hit->u_mm;
          s.slope = profile_slope(hit->normal, seed.normal);
          st.surface_id = hit->surface_id;
          top_normal = hit->normal;
        }
      }
      ProfileFit fit = fit_profile(samples, zb, zt, params.fit);
      if (fit.cuts.empty()) fit.cuts.push_back({0.0, 0.0});  // nothing found: the outline itself
      st.shape = fit.shape;
      st.slope_rule_agrees = fit.slope_rule_agrees;
      st.tilt_limited = fit.tilt_limited;
      st.max_deviation_mm = fit.max_deviation_mm;
      outline.max_deviation_mm = std::max(outline.max_deviation_mm, fit.max_deviation_mm);
      ++plan.shape_counts[static_cast<std::size_t>(fit.shape)];
      // The paper's V = N × C: C along the contour (material on its left), N the facet normal.
      const Eigen::Vector3d c_dir(-seed.normal.y(), seed.normal.x(), 0.0);
      Eigen::Vector3d v = top_normal.cross(c_dir);
      paper_vs.push_back(v.norm() > 1e-12 ? Eigen::Vector3d(v.normalized()) : Eigen::Vector3d::Zero());
      outline.stations.push_back(st);
      fits.push_back(std::move(fit));
    }
    std::size_t pass_count = 1;
    for (const auto& f : fits) pass_count = std::max(pass_count, f.cuts.size());
    outline.passes.resize(pass_count);
    for (std::size_t p = 0; p < pass_count; ++p) {
      CutPass& pass = outline.passes[p];
      pass.lines.reserve(fits.size());
      for (std::size_t s = 0; s < fits.size(); ++s) {
        const auto& cuts = fits[s].cuts;
        // Stations with one cut repeat it: every pass is a closed loop around the outline.
        const CutLine1D& cut = cuts[std::min(p * cuts.size() / pass_count, cuts.size() - 1)];
        pass.lines.push_back(make_line(outline.stations[s], cut, zb, zt, paper_vs[s]));
      }
      unwind_c(pass);
    }
    plan.passes = std::max(plan.passes, static_cast<int>(pass_count));
    plan.max_deviation_mm = std::max(plan.max_deviation_mm, outline.max_deviation_mm);
    plan.outlines.push_back(std::move(outline));
  }
  plan.within_tolerance = plan.max_deviation_mm <= params.tolerance_mm;
  return plan;
}

}  // namespace

std::expected<BevelPlan, Error> plan_bevels(const Mesh& mesh, std::span<const LayerSpan> layers,
                                            const BevelParams& params) {
  if (!(params.sub_slice_mm > 0.0) || !std::isfinite(params.sub_slice_mm)) {
    return std::unexpected(Error{ErrorCode::invalid_argument, fmt::format("sub-slice spacing must be > 0 mm (got {})", params.sub_slice_mm)});
  }
  if (!(params.fit.tilt_max_rad >= 0.0) || params.fit.tilt_max_rad >= 0.5 * M_PI) {
    return std::unexpected(Error{ErrorCode::invalid_argument, fmt::format("tilt limit must be in [0°, 90°) (got {:.3f}°)", params.fit.tilt_max_rad * 180.0 / M_PI)});
  }
  std::vector<double> all_z;
  std::vector<std::size_t> first(layers.size() + 1, 0);
  std::vector<std::vector<double>> layer_z(layers.size());
  for (std::size_t i = 0; i < layers.size(); ++i) {
    const auto& l = layers[i];
    if (!(l.thickness_mm > 0.0) || !std::isfinite(l.z_bottom_mm)) {
      return std::unexpected(Error{ErrorCode::invalid_argument, fmt::format("layer {}: thickness must be > 0 mm (got {})", i, l.thickness_mm)});
    }
    if (i > 0 && l.z_bottom_mm < layers[i - 1].z_top_mm() - 1e-9) {
      return std::unexpected(Error{ErrorCode::invalid_argument,
                                   fmt::format("layer {} starts at z = {} mm, below the top of layer {} ({} mm)", i, l.z_bottom_mm, i - 1, layers[i - 1].z_top_mm())});
    }
    layer_z[i] = sub_slice_heights(l.z_bottom_mm, l.thickness_mm, params.sub_slice_mm);
    first[i] = all_z.size();
    all_z.insert(all_z.end(), layer_z[i].begin(), layer_z[i].end());
  }
  first[layers.size()] = all_z.size();
  SliceParams slice_params;
  slice_params.parallel = params.parallel;
  auto slices = slice_mesh(mesh, all_z, slice_params);
  if (!slices) return std::unexpected(slices.error());

  BevelPlan plan;
  plan.fit = params.fit;
  plan.layers.resize(layers.size());
  auto one = [&](std::size_t i) {
    std::vector<const Slice*> subs;
    for (std::size_t k = first[i]; k < first[i + 1]; ++k) subs.push_back(&(*slices)[k]);
    plan.layers[i] = plan_layer(mesh, layers[i], static_cast<int>(i), layer_z[i], subs, params);
  };
  if (params.parallel) {
    tbb::parallel_for(std::size_t{0}, layers.size(), one);
  } else {
    for (std::size_t i = 0; i < layers.size(); ++i) one(i);
  }
  return plan;
}

}  // namespace lamina
