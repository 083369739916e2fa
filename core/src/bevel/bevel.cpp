// The bevel plan (paper 3-4, 3-5): per layer, the outline every sub-slice fits in (the vertical
// "outside" edge), stations along it, each station's profile read on every sub-slice along its
// normal, the cut lines fitted to that profile, and passes assembled from the lines.
#include "lamina/core/bevel.hpp"

#include "bevel/plan_layers.hpp"
#include "bevel/bevel_gouge.hpp"
#include "bevel/bevel_outline.hpp"
#include "bevel/facets_by_z.hpp"
#include "geometry/clipper_bridge.hpp"
#include "lamina/core/section_lines.hpp"
#include "lamina/core/slice.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

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
using bevel_detail::layer_outline_rings;
using bevel_detail::outline_section;
using bevel_detail::OutlineRing;
using bevel_detail::station_seeds;
using bevel_detail::StationSeed;

// Material that lies between two sub-slices and outside both: a bore's underside, the top of a
// dome, a step — where the surface turns (nearly) horizontal between two thin slices. Such a
// facet's part inside the layer is projected onto the layer's outline; facets whose clipped
// corners all sit inside a neighbouring sub-slice add nothing and are skipped (the common case
// on smooth surfaces, and what keeps this cheap).
ClipperLib::Paths facet_shadows(const Mesh& mesh, const std::vector<std::uint32_t>& slab_facets, const std::vector<double>& zs,
                                const std::vector<SectionLines>& sections) {
  ClipperLib::Paths shadows;
  // Between the outer sub-slices, which are read just inside the faces: a flat face of the
  // model lying on a layer face belongs to the neighbouring layer.
  const double zb = zs.front(), zt = zs.back();
  std::vector<Eigen::Vector3d> poly, next;
  auto inside_neighbour = [&](const Eigen::Vector3d& v) {
    const auto it = std::upper_bound(zs.begin(), zs.end(), v.z());
    const std::size_t hi = std::min<std::size_t>(static_cast<std::size_t>(it - zs.begin()), zs.size() - 1);
    const std::size_t lo = hi > 0 ? hi - 1 : 0;
    const Eigen::Vector2d p = v.head<2>();
    return sections[lo].contains(p) || sections[hi].contains(p);
  };
  // A vertex is a corner of about six facets, an edge's midpoint is on two: their answers are
  // kept (0 unknown, 1 outside, 2 inside).
  std::vector<std::uint8_t> vertex_inside(mesh.vertices.size(), 0), midpoint_inside;
  const bool edges_known = mesh.face_edges.size() == mesh.faces.size();
  if (edges_known) midpoint_inside.assign(mesh.edges.size(), 0);
  auto kept = [&](std::uint8_t& known, const Eigen::Vector3d& p) {
    if (known == 0) known = inside_neighbour(p) ? 2 : 1;
    return known == 2;
  };
  auto vertex_inside_neighbour = [&](std::int32_t v) {
    return kept(vertex_inside[static_cast<std::size_t>(v)], mesh.vertices[static_cast<std::size_t>(v)]);
  };
  for (const std::uint32_t f : slab_facets) {  // the facets whose z range meets [zb, zt]
    if (std::abs(mesh.normals[f].z()) < 0.02) continue;  // a wall: its shadow is a line
    const auto& tri = mesh.faces[f];
    const Eigen::Vector3d& a = mesh.vertices[static_cast<std::size_t>(tri[0])];
    const Eigen::Vector3d& b = mesh.vertices[static_cast<std::size_t>(tri[1])];
    const Eigen::Vector3d& c = mesh.vertices[static_cast<std::size_t>(tri[2])];
    const double lo = std::min({a.z(), b.z(), c.z()}), hi = std::max({a.z(), b.z(), c.z()});
    const bool unclipped = lo >= zb && hi <= zt;  // its corners are the mesh's vertices
    // Clip to zb ≤ z ≤ zt (Sutherland–Hodgman on the two planes).
    poly.assign({a, b, c});
    for (int side = 0; side < 2 && !poly.empty(); ++side) {
      next.clear();
      auto keep = [&](const Eigen::Vector3d& v) { return side == 0 ? v.z() >= zb : v.z() <= zt; };
      const double plane = side == 0 ? zb : zt;
      for (std::size_t i = 0; i < poly.size(); ++i) {
        const Eigen::Vector3d& p = poly[i];
        const Eigen::Vector3d& q = poly[(i + 1) % poly.size()];
        if (keep(p)) next.push_back(p);
        if (keep(p) != keep(q)) next.push_back(p + (q - p) * ((plane - p.z()) / (q.z() - p.z())));
      }
      poly.swap(next);
    }
    if (poly.size() < 3) continue;
    // Corners, edge midpoints and the centre: a facet bridging a hole of its neighbours (a
    // tunnel's roof) has its corners inside but not its middle.
    bool all_inside = true;
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();
    for (std::size_t i = 0; i < poly.size() && all_inside; ++i) {
      centre += poly[i];
      const bool corner = unclipped ? vertex_inside_neighbour(tri[i]) : inside_neighbour(poly[i]);
      // The same midpoint, the same point, from both facets of an edge (a + b = b + a).
      const Eigen::Vector3d mid = 0.5 * (poly[i] + poly[(i + 1) % poly.size()]);
      all_inside = corner && (unclipped && edges_known
                                  ? kept(midpoint_inside[static_cast<std::size_t>(mesh.face_edges[f][i])], mid)
                                  : inside_neighbour(mid));
    }
    all_inside = all_inside && inside_neighbour(centre / static_cast<double>(poly.size()));
    if (all_inside) continue;
    Polygon2 ring;
    for (const auto& v : poly) ring.emplace_back(v.x(), v.y());
    if (signed_area_mm2(ring) < 0) std::reverse(ring.begin(), ring.end());
    shadows.push_back(geometry_detail::to_clipper(ring));
  }
  return shadows;
}

// The facets inside a layer, bucketed by their footprint, so that a station can read the exact
// trace of the surface in its profile plane (every facet the plane cuts), not only the points
// on the sub-slices.
class SlabFacets {
 public:
  // `slab_facets`: the facets whose z range meets [zb, zt], ascending.
  SlabFacets(const Mesh& mesh, const std::vector<std::uint32_t>& slab_facets, double zb, double zt, double cell_mm)
      : mesh_(mesh), zb_(zb), zt_(zt), facets_(slab_facets) {
    std::vector<Box2> footprints;
    footprints.reserve(facets_.size());
    for (const std::uint32_t f : facets_) {
      const auto [a, b, c] = corners(f);
      footprints.push_back({a.head<2>().cwiseMin(b.head<2>()).cwiseMin(c.head<2>()),
                            a.head<2>().cwiseMax(b.head<2>()).cwiseMax(c.head<2>())});
    }
    grid_ = BoxGrid(footprints, [&](const Eigen::Vector2d& size, std::size_t count) {
      return std::max({cell_mm, std::sqrt(size.x() * size.y() / static_cast<double>(count)),
                       std::max(size.x(), size.y()) / 2048.0});
    });
    stamp_.assign(facets_.size(), 0u);
  }

  // Points of the surface's trace in the vertical plane through `base` along `n`, for u in
  // [u_min, u_max] and z in the layer: the ends of every facet's cut by the plane, clipped.
  void trace(const Eigen::Vector2d& base, const Eigen::Vector2d& n, double u_min, double u_max,
             std::vector<ProfileBound>& out, std::vector<std::uint32_t>& seen) const {
    out.clear();
    seen.clear();
    if (facets_.empty()) return;
    const Eigen::Vector2d t(-n.y(), n.x());
    const double len = u_max - u_min;
    const double cell_mm = grid_.cell_mm();
    const int steps = std::max(1, static_cast<int>(std::ceil(len / (0.5 * cell_mm))));
    // The cells the line passes (and their neighbours: it may cut a corner between two
    // samples), each once; then their facets, each once (stamped).
    cells_.clear();
    for (int k = 0; k <= steps; ++k) {
      const Eigen::Vector2d p = (base + (u_min + len * k / steps) * n - grid_.origin()) / cell_mm;
      const int cx = static_cast<int>(std::floor(p.x())), cy = static_cast<int>(std::floor(p.y()));
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          const int x = cx + dx, y = cy + dy;
          if (x < 0 || y < 0 || x >= grid_.nx() || y >= grid_.ny()) continue;
          cells_.push_back(static_cast<std::uint32_t>(grid_.cell(x, y)));
        }
      }
    }
    std::sort(cells_.begin(), cells_.end());
    cells_.erase(std::unique(cells_.begin(), cells_.end()), cells_.end());
    if (++generation_ == 0) {
      std::fill(stamp_.begin(), stamp_.end(), 0u);
      generation_ = 1;
    }
    for (std::uint32_t c : cells_) {
      for (const std::uint32_t local : grid_.items(c)) {
        if (stamp_[local] == generation_) continue;
        stamp_[local] = generation_;
        seen.push_back(facets_[local]);
      }
    }
    for (std::uint32_t f : seen) {
      const auto [a, b, c] = corners(f);
      const Eigen::Vector3d v[3] = {a, b, c};
      double d[3];
      for (int i = 0; i < 3; ++i) d[i] = (v[i].head<2>() - base).dot(t);
      Eigen::Vector2d ends[2];  // (u, z)
      int found = 0;
      for (int i = 0; i < 3 && found < 2; ++i) {
        const int j = (i + 1) % 3;
        if ((d[i] < 0) == (d[j] < 0)) continue;
        const double s = d[i] / (d[i] - d[j]);
        const Eigen::Vector3d q = v[i] + s * (v[j] - v[i]);
        ends[found++] = Eigen::Vector2d((q.head<2>() - base).dot(n), q.z());
      }
      if (found < 2) continue;
      clip_and_add(ends[0], ends[1], u_min, u_max, out);
    }
  }

 private:
  std::array<Eigen::Vector3d, 3> corners(std::size_t f) const {
    const auto& tri = mesh_.faces[f];
    return {mesh_.vertices[static_cast<std::size_t>(tri[0])], mesh_.vertices[static_cast<std::size_t>(tri[1])],
            mesh_.vertices[static_cast<std::size_t>(tri[2])]};
  }

  // Clip the segment a–b (u, z) to the layer's z range and the u window; add its ends.
  void clip_and_add(Eigen::Vector2d a, Eigen::Vector2d b, double u_min, double u_max, std::vector<ProfileBound>& out) const {
    double t0 = 0.0, t1 = 1.0;
    const Eigen::Vector2d d = b - a;
    auto clip = [&](double p, double q) {  // keep where p·t ≤ q
      if (std::abs(p) < 1e-300) return q >= 0;
      const double r = q / p;
      if (p < 0) t0 = std::max(t0, r); else t1 = std::min(t1, r);
      return t0 <= t1;
    };
    if (!clip(-d.y(), a.y() - zb_) || !clip(d.y(), zt_ - a.y()) || !clip(-d.x(), a.x() - u_min) || !clip(d.x(), u_max - a.x())) return;
    const Eigen::Vector2d p = a + t0 * d, q = a + t1 * d;
    out.push_back({p.y(), p.x()});
    out.push_back({q.y(), q.x()});
  }

  const Mesh& mesh_;
  double zb_, zt_;
  std::vector<std::uint32_t> facets_;
  BoxGrid grid_;  // cell → index into facets_ (the footprints', in the same order)
  // Per-query scratch: one SlabFacets serves one layer on one thread.
  mutable std::vector<std::uint32_t> stamp_, cells_;
  mutable std::uint32_t generation_ = 0;
};

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

// The outline here comes from material between sub-slices (a shadow), which the profile cannot
// see: only the vertical cut on the outline is sure to stay outside.
constexpr double kOnOutline = 1e-3;  // the outline went through Clipper (1 nm grid), cleaned at 0.1 µm

// What one layer's stations read: its sub-slices' lines, the facets between them, the outline.
struct StationContext {
  const std::vector<SectionLines>& lines;
  const SlabFacets& slab;
  const SectionLines& outline_lines;
  const std::vector<double>& zs;
  double zb, zt, reach;
  const BevelParams& params;
  // How far off the material the ring being planned may stand: the simplification's, for a ring
  // it simplified (simplified_off_material), else 0. A ring kept whole is on the material, and
  // a station whose nearest sample lies further in than kOnOutline stands on a shadow
  // (openscad_example001 at z 22.5: with 21 µm for every ring, such stations got a profile of
  // three passes that gouged, 0.374 mm instead of 0.075).
  double off_material_mm;
  std::vector<ProfileSample> samples;
  std::vector<ProfileBound> trace;
  std::vector<std::uint32_t> scratch;
};

struct StationPlan {
  CutStation station;
  ProfileFit fit;
  Eigen::Vector3d paper_v = Eigen::Vector3d::Zero();  // the paper's V = N × C
};

StationPlan plan_station(const StationSeed& seed, StationContext& cx) {
  StationPlan out;
  CutStation& st = out.station;
  st.base_mm = seed.point;
  st.normal = seed.normal;
  Eigen::Vector3d top_normal = Eigen::Vector3d::Zero();
  for (std::size_t j = 0; j < cx.zs.size(); ++j) {
    ProfileSample& s = cx.samples[j];
    s.z_mm = cx.zs[j];
    const auto hit = cx.lines[j].exit_crossing(seed.point, seed.normal, -cx.reach, kOnOutline, CrossingPick::largest);
    s.present = hit.has_value();
    if (hit) {
      s.u_mm = hit->u_mm;
      s.slope = profile_slope(hit->normal, seed.normal);
      st.surface_id = hit->surface_id;
      top_normal = hit->normal;
    }
  }
  cx.slab.trace(seed.point, seed.normal, -cx.reach, kOnOutline, cx.trace, cx.scratch);
  // Walking out along the normal, the next material of the layer (leaving it along −n).
  double ceiling = std::numeric_limits<double>::infinity();
  if (const auto next = cx.outline_lines.exit_crossing(seed.point, -seed.normal, -cx.reach, -2 * kOnOutline,
                                                       CrossingPick::largest))
    ceiling = -next->u_mm - kOnOutline;
  out.fit = fit_profile(cx.samples, cx.zb, cx.zt, cx.params.fit, cx.trace, ceiling);
  double outermost = -std::numeric_limits<double>::infinity();
  for (const auto& smp : cx.samples)
    if (smp.present) outermost = std::max(outermost, smp.u_mm);
  // A simplified ring stands up to twice the simplification off the material.
  const double on_outline = kOnOutline + 2.0 * cx.off_material_mm;
  if (out.fit.cuts.empty() || outermost < -on_outline) {  // a shadow: the vertical cut on the outline
    const double gap = std::isfinite(outermost) ? -outermost : 0.0;
    out.fit.cuts.assign(1, CutLine1D{0.0, 0.0});
    out.fit.max_deviation_mm = std::max(out.fit.max_deviation_mm, gap);
  }
  st.shape = out.fit.shape;
  st.slope_rule_agrees = out.fit.slope_rule_agrees;
  st.tilt_limited = out.fit.tilt_limited;
  st.max_deviation_mm = out.fit.max_deviation_mm;
  // The paper's V = N × C: C along the contour (material on its left), N the facet normal.
  const Eigen::Vector3d c_dir(-seed.normal.y(), seed.normal.x(), 0.0);
  const Eigen::Vector3d v = top_normal.cross(c_dir);
  out.paper_v = v.norm() > 1e-12 ? Eigen::Vector3d(v.normalized()) : Eigen::Vector3d::Zero();
  return out;
}

// The outline's passes: as many as its station with the most cuts; stations with one cut repeat
// it, so every pass is a closed loop around the outline.
void make_passes(LayerOutline& outline, const std::vector<ProfileFit>& fits, const std::vector<Eigen::Vector3d>& paper_vs,
                 double zb, double zt) {
  std::size_t pass_count = 1;
  for (const auto& f : fits) pass_count = std::max(pass_count, f.cuts.size());
  outline.passes.resize(pass_count);
  for (std::size_t p = 0; p < pass_count; ++p) {
    CutPass& pass = outline.passes[p];
    pass.lines.reserve(fits.size());
    for (std::size_t s = 0; s < fits.size(); ++s) {
      const auto& cuts = fits[s].cuts;
      const CutLine1D& cut = cuts[std::min(p * cuts.size() / pass_count, cuts.size() - 1)];
      pass.lines.push_back(make_line(outline.stations[s], cut, zb, zt, paper_vs[s]));
    }
    unwind_c(pass);
  }
}

LayerOutline plan_outline(const OutlineRing& ring, double simplify_mm, StationContext& cx, LayerPlan& plan,
                          std::vector<char>& loose) {
  LayerOutline outline;
  outline.is_hole = ring.is_hole;
  outline.parent = ring.parent;
  cx.off_material_mm = ring.chord.empty() ? 0.0 : simplify_mm;
  const auto seeds = station_seeds(ring, cx.params.station_spacing_mm);
  loose.clear();
  for (const StationSeed& seed : seeds) loose.push_back(seed.loose ? 1 : 0);
  std::vector<ProfileFit> fits;
  std::vector<Eigen::Vector3d> paper_vs;
  fits.reserve(seeds.size());
  for (const StationSeed& seed : seeds) {
    StationPlan sp = plan_station(seed, cx);
    outline.max_deviation_mm = std::max(outline.max_deviation_mm, sp.fit.max_deviation_mm);
    ++plan.shape_counts[static_cast<std::size_t>(sp.fit.shape)];
    paper_vs.push_back(sp.paper_v);
    outline.stations.push_back(sp.station);
    fits.push_back(std::move(sp.fit));
  }
  make_passes(outline, fits, paper_vs, cx.zb, cx.zt);
  return outline;
}

}  // namespace

namespace {

// What the cuts of one layer's outlines are made from, whatever rings are taken.
struct LayerInputs {
  const Mesh& mesh;
  const std::vector<const Slice*>& sub_slices;
  const std::vector<SectionLines>& lines;
  const SlabFacets& slab;
  const ClipperLib::Paths& shadows;
  const std::vector<double>& zs;
  const LayerSpan& span;
  double reach;
  const BevelParams& params;
};

LayerPlan empty_plan(const LayerInputs& in, int index) {
  LayerPlan plan;
  plan.index = index;
  plan.z_bottom_mm = in.span.z_bottom_mm;
  plan.thickness_mm = in.span.thickness_mm;
  plan.sub_slice_z_mm = in.zs;
  return plan;
}

// The layer's outlines, their rings simplified by simplify_mm (0: every corner a station), cut
// and (outside cuts) kept off the model's material between stations. Returns the deepest gouge
// the clearing found, before it moved stations, between two stations on a chord of the
// simplification away from sharp corners (StationSeed::loose).
double cut_outlines(const LayerInputs& in, double simplify_mm, LayerPlan& plan) {
  const auto rings =
      layer_outline_rings(in.sub_slices, in.shadows, in.params.min_hole_width_mm, simplify_mm, plan.outline_simplified);
  const SectionLines outline_lines(in.mesh, outline_section(rings));
  StationContext cx{in.lines, in.slab, outline_lines, in.zs, in.span.z_bottom_mm, in.span.z_top_mm(), in.reach,
                    in.params, 0.0, std::vector<ProfileSample>(in.zs.size()), {}, {}};
  std::vector<std::vector<char>> loose(rings.size());
  for (std::size_t r = 0; r < rings.size(); ++r) {
    LayerOutline outline = plan_outline(rings[r], simplify_mm, cx, plan, loose[r]);
    plan.passes = std::max(plan.passes, static_cast<int>(outline.passes.size()));
    plan.max_deviation_mm = std::max(plan.max_deviation_mm, outline.max_deviation_mm);
    plan.outlines.push_back(std::move(outline));
  }
  if (in.params.fit.side != CutSide::outside) return 0.0;
  const bevel_detail::GougeClearance g = bevel_detail::clear_gouges(plan, in.sub_slices, in.lines, in.reach, &loose);
  plan.gouge_shift_mm = g.largest_shift_mm;
  plan.gouge_left_mm = g.worst_left_mm;
  return g.worst_found_loose_mm;
}

}  // namespace

LayerPlan bevel_detail::plan_layer(const Mesh& mesh, const bevel_detail::FacetsByZ& facets_by_z, const LayerSpan& span,
                                   int index, const std::vector<double>& zs, const std::vector<const Slice*>& sub_slices, const BevelParams& params) {
  std::vector<SectionLines> lines;
  lines.reserve(sub_slices.size());
  for (const Slice* s : sub_slices) lines.emplace_back(mesh, *s, SectionQueries::crossings_and_contains);
  // How far in a sample may lie and still be this station's surface: what a line at the tilt
  // limit reaches across the layer, plus a sub-slice of slack. Further in, the surface has
  // turned (nearly) horizontal: the sample counts as absent and the profile gets a ledge.
  const double tan_max = std::tan(std::min(params.fit.tilt_max_rad, 1.5));
  const double reach = span.thickness_mm * std::max(tan_max, 1.0) + 2.0 * params.sub_slice_mm;
  std::vector<std::uint32_t> slab_facets;
  facets_by_z.in_slab(zs.front(), zs.back(), slab_facets);
  const SlabFacets slab(mesh, slab_facets, zs.front(), zs.back(), params.station_spacing_mm);
  const ClipperLib::Paths shadows = facet_shadows(mesh, slab_facets, zs, lines);
  const LayerInputs in{mesh, sub_slices, lines, slab, shadows, zs, span, reach, params};

  // Simplified outlines only for outside cuts, whose chords between stations the gouge clearing
  // checks against every sub-slice: when those on the simplification's chords took more of the
  // part than a tenth of the tolerance (or twice the simplification), the corners dropped were
  // where the cut turns (a twisted prism's corner sweeps along its outline) and the layer is cut
  // from every corner. A gouge at a sharp corner (a corner on a sloped face) is no reason: the
  // corner is a station either way (openscad_example006: 205 layers planned twice for it).
  const double simplify = params.fit.side == CutSide::outside ? std::max(0.0, params.outline_simplify_mm) : 0.0;
  LayerPlan plan = empty_plan(in, index);
  const double gouge = cut_outlines(in, simplify, plan);
  if (simplify > 0.0 && gouge > std::max(2.0 * simplify, 0.1 * params.tolerance_mm)) {
    plan = empty_plan(in, index);
    cut_outlines(in, 0.0, plan);
  }
  plan.within_tolerance = plan.max_deviation_mm <= params.tolerance_mm;
  return plan;
}

}  // namespace lamina
