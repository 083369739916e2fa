// How far the stack is from the model: the volume of their symmetric difference from the XOR
// areas (Clipper) of horizontal sections, and the largest distance between their surfaces
// (deviation_distance.cpp).
//
// Sections are taken every step over z, in the middle of each step; a step that a layer face
// crosses is split there and each part measured in its own middle (weighted by its length), so a
// face (or a bonding gap) between two sections is integrated exactly instead of rounded to a
// whole step.
#include "lamina/core/deviation.hpp"

#include "geometry/clipper_bridge.hpp"
#include "lamina/core/slice.hpp"
#include "deviation/surface_distance.hpp"

#include <Eigen/Geometry>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace lamina {

namespace {

std::unexpected<Error> invalid_input(std::string message) {
  return std::unexpected(Error{ErrorCode::invalid_argument, std::move(message)});
}

// Signed volume by the divergence theorem, about the box centre (keeps the sum well conditioned).
double mesh_volume(const Mesh& mesh) {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const auto& v : mesh.vertices) {
    lo = lo.cwiseMin(v);
    hi = hi.cwiseMax(v);
  }
  const Eigen::Vector3d c = 0.5 * (lo + hi);
  double six = 0.0;
  for (const auto& f : mesh.faces) {
    const Eigen::Vector3d a = mesh.vertices[static_cast<std::size_t>(f[0])] - c;
    const Eigen::Vector3d b = mesh.vertices[static_cast<std::size_t>(f[1])] - c;
    const Eigen::Vector3d d = mesh.vertices[static_cast<std::size_t>(f[2])] - c;
    six += a.dot(b.cross(d));
  }
  return six / 6.0;
}

std::expected<void, Error> check_plan(const BevelPlan& plan) {
  bool any = false;
  for (std::size_t l = 0; l < plan.layers.size(); ++l) {
    const LayerPlan& layer = plan.layers[l];
    if (!std::isfinite(layer.z_bottom_mm) || !(layer.thickness_mm > 0.0) || !std::isfinite(layer.thickness_mm))
      return invalid_input(fmt::format("measure_deviation: layer {} has z_bottom {} and thickness {} (need finite, thickness > 0)",
                             l, layer.z_bottom_mm, layer.thickness_mm));
    for (std::size_t o = 0; o < layer.outlines.size(); ++o) {
      const LayerOutline& outline = layer.outlines[o];
      if (!geometry_detail::outline_usable(outline))
        return invalid_input(fmt::format("measure_deviation: layer {} outline {} is not usable ({} stations, {} passes; need "
                               ">= 3 stations, one line per station in every pass, finite points)",
                               l, o, outline.stations.size(), outline.passes.size()));
      any = any || !outline.is_hole;
    }
  }
  if (!any) return invalid_input("measure_deviation: the plan has no outline (no stack to compare)");
  return {};
}

// Wall samples the distance estimate will take (stations and points between them, at heights
// distance_sample_mm apart), so that a tiny spacing is refused instead of exhausting memory.
double wall_sample_estimate(const BevelPlan& plan, double ds) {
  double total = 0.0;
  for (const auto& layer : plan.layers) {
    const double heights = std::ceil(layer.thickness_mm / ds) + 1.0;
    for (const auto& outline : layer.outlines) {
      double length = 0.0;
      const std::size_t n = outline.stations.size();
      for (std::size_t i = 0; i < n; ++i)
        length += (outline.stations[(i + 1) % n].base_mm - outline.stations[i].base_mm).norm();
      total += (static_cast<double>(n) + length / ds) * heights;
    }
  }
  return total;
}

struct SectionAreas {
  double xor_mm2 = 0.0, stack_mm2 = 0.0;
};

// One section: the model's (its slice) against the stack's (the layers cut there), as
// |A xor B| = |A| + |B| − 2 |A ∩ B|: Clipper's XOR of two nearly equal sections returns thousands
// of slivers and sorts out their nesting in quadratic time; the intersection is one clean polygon.
SectionAreas section_areas(const Slice& slice, const BevelPlan& plan, double z) {
  ClipperLib::Paths stack;
  int layers_here = 0;
  for (const auto& layer : plan.layers) {
    if (!(z >= layer.z_bottom_mm && z <= layer.z_top_mm())) continue;
    const auto section = geometry_detail::to_clipper(layer_section(layer, z));
    stack.insert(stack.end(), section.begin(), section.end());
    ++layers_here;
  }
  if (layers_here > 1) {  // overlapping layers: their union
    ClipperLib::Clipper u;
    u.AddPaths(stack, ClipperLib::ptSubject, true);
    u.Execute(ClipperLib::ctUnion, stack, ClipperLib::pftPositive, ClipperLib::pftPositive);
  }
  SectionAreas r;
  r.stack_mm2 = geometry_detail::area_mm2(stack);
  const ClipperLib::Paths model = geometry_detail::slice_material(slice);
  const double model_area = geometry_detail::area_mm2(model);
  double common = 0.0;
  if (!model.empty() && !stack.empty()) {
    ClipperLib::Clipper c;
    c.AddPaths(model, ClipperLib::ptSubject, true);
    c.AddPaths(stack, ClipperLib::ptClip, true);
    ClipperLib::Paths both;
    c.Execute(ClipperLib::ctIntersection, both, ClipperLib::pftPositive, ClipperLib::pftPositive);
    common = geometry_detail::area_mm2(both);
  }
  r.xor_mm2 = std::max(0.0, model_area + r.stack_mm2 - 2.0 * common);
  return r;
}

// The sections' heights and widths: every step over the z range of both solids, split at every
// layer face; each measured in its middle.
struct Sections {
  std::vector<double> mids, widths;
};

std::expected<Sections, Error> sections_of(const Mesh& mesh, const BevelPlan& plan, double step_mm) {
  double z_lo = std::numeric_limits<double>::infinity(), z_hi = -z_lo;
  for (const auto& v : mesh.vertices) {
    z_lo = std::min(z_lo, v.z());
    z_hi = std::max(z_hi, v.z());
  }
  z_lo = std::min(z_lo, 0.0);
  for (const auto& layer : plan.layers) {
    z_lo = std::min(z_lo, layer.z_bottom_mm);
    z_hi = std::max(z_hi, layer.z_top_mm());
  }
  const double steps = std::ceil((z_hi - z_lo) / step_mm);
  if (steps > kMaxDeviationSections)
    return invalid_input(fmt::format("measure_deviation: {:.4g} mm at step {} mm is more than {:.0f} sections", z_hi - z_lo,
                           step_mm, kMaxDeviationSections));
  const auto n_steps = std::max<std::size_t>(1, static_cast<std::size_t>(steps));
  std::vector<double> breaks;
  breaks.reserve(n_steps + 1 + 2 * plan.layers.size());
  for (std::size_t k = 0; k <= n_steps; ++k) breaks.push_back(z_lo + static_cast<double>(k) * step_mm);
  const double first = breaks.front(), last = breaks.back();
  for (const auto& layer : plan.layers)
    for (const double z : {layer.z_bottom_mm, layer.z_top_mm()})
      if (z > first && z < last) breaks.push_back(z);
  std::sort(breaks.begin(), breaks.end());
  Sections s;
  s.mids.reserve(breaks.size());
  s.widths.reserve(breaks.size());
  for (std::size_t i = 0; i + 1 < breaks.size(); ++i) {
    const double w = breaks[i + 1] - breaks[i];
    if (!(w > 1e-9)) continue;
    s.mids.push_back(0.5 * (breaks[i] + breaks[i + 1]));
    s.widths.push_back(w);
  }
  return s;
}

std::expected<void, Error> check_deviation_params(const DeviationParams& params) {
  if (!(params.step_mm > 0.0) || !std::isfinite(params.step_mm))
    return invalid_input(fmt::format("measure_deviation: step_mm must be finite and > 0 (got {})", params.step_mm));
  if (!(params.distance_sample_mm > 0.0) || !std::isfinite(params.distance_sample_mm))
    return invalid_input(fmt::format("measure_deviation: distance_sample_mm must be finite and > 0 (got {})",
                           params.distance_sample_mm));
  return {};
}

}  // namespace

std::expected<Deviation, Error> measure_deviation(const Mesh& mesh, const BevelPlan& plan,
                                                  const DeviationParams& params) {
  if (auto ok = check_deviation_params(params); !ok) return std::unexpected(ok.error());
  if (mesh.faces.empty() || mesh.vertices.empty())
    return std::unexpected(Error{ErrorCode::empty_mesh, "measure_deviation: the mesh has no facet"});
  if (auto ok = check_plan(plan); !ok) return std::unexpected(ok.error());
  constexpr double kMaxWallSamples = 5e7;
  if (const double samples = wall_sample_estimate(plan, params.distance_sample_mm); samples > kMaxWallSamples)
    return invalid_input(fmt::format("measure_deviation: distance_sample_mm {} would take {:.3g} wall samples (more than {:.0e})",
                           params.distance_sample_mm, samples, kMaxWallSamples));
  auto sections = sections_of(mesh, plan, params.step_mm);
  if (!sections) return std::unexpected(sections.error());
  const std::vector<double>& mids = sections->mids;

  // Each section measured as it is cut and dropped (all 1000 of the 1M sphere at once were ~90 MB);
  // summed afterwards in section order, so the total does not depend on threads.
  SliceParams slice_params;
  slice_params.parallel = params.parallel;
  std::vector<SectionAreas> areas(mids.size());
  auto cut = for_each_slice(mesh, mids, slice_params,
                            [&](std::size_t i, Slice&& slice) { areas[i] = section_areas(slice, plan, mids[i]); });
  if (!cut) return std::unexpected(cut.error());

  Deviation d;
  for (std::size_t i = 0; i < mids.size(); ++i) {
    d.volume_mm3 += areas[i].xor_mm2 * sections->widths[i];
    d.stack_volume_mm3 += areas[i].stack_mm2 * sections->widths[i];
  }
  d.model_volume_mm3 = mesh_volume(mesh);
  d.volume_pct = d.model_volume_mm3 > 0.0 ? 100.0 * d.volume_mm3 / d.model_volume_mm3 : 0.0;
  const deviation_detail::FarthestPoint far = deviation_detail::max_surface_distance(mesh, plan, params);
  d.max_mm = far.distance;
  d.max_at_mm = far.at;
  return d;
}

}  // namespace lamina
