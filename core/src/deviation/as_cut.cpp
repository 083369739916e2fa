// The as-cut part against the model, beside the plan (as_cut.hpp): pieces matched to parts in
// the sheet frame, mapped back into the layer's frame, and each layer measured slab by slab.
#include "lamina/core/as_cut.hpp"

#include "geometry/clipper_bridge.hpp"
#include "geometry/closest_point.hpp"
#include "lamina/core/deviation.hpp"
#include "lamina/core/slice.hpp"

#include <Eigen/Geometry>
#include <fmt/format.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

namespace lamina {
namespace {

namespace gd = geometry_detail;

std::unexpected<Error> bad(std::string message) {
  return std::unexpected(Error{ErrorCode::invalid_argument, std::move(message)});
}

Eigen::Rotation2Dd rotation_of(const Placement& pl) { return Eigen::Rotation2Dd(pl.rotation_rad); }

// sheet_xy = R · layer_xy + offset, and back.
Polygon2 to_sheet(const Polygon2& ring, const Placement& pl) {
  Polygon2 out;
  out.reserve(ring.size());
  for (const auto& p : ring) out.push_back(rotation_of(pl) * p + pl.offset_mm);
  return out;
}
Polygon2 to_layer(const Polygon2& ring, const Placement& pl) {
  Polygon2 out;
  out.reserve(ring.size());
  for (const auto& p : ring) out.push_back(rotation_of(pl).inverse() * (p - pl.offset_mm));
  return out;
}

struct Box {
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  void add(const Polygon2& ring) {
    for (const auto& p : ring) {
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
  }
  bool meets(const Box& o) const { return (lo.array() <= o.hi.array()).all() && (o.lo.array() <= hi.array()).all(); }
};

double intersection_mm2(const ClipperLib::Paths& a, const ClipperLib::Paths& b) {
  ClipperLib::Clipper c;
  c.AddPaths(a, ClipperLib::ptSubject, true);
  c.AddPaths(b, ClipperLib::ptClip, true);
  ClipperLib::Paths both;
  c.Execute(ClipperLib::ctIntersection, both, ClipperLib::pftNonZero, ClipperLib::pftNonZero);
  return gd::area_mm2(both);
}

// One slab of one layer: its middle height, its height, the as-cut and planned sections (layer
// frame, build XY).
struct Slab {
  std::size_t layer_slot = 0;
  double z_mm = 0.0, height_mm = 0.0;
  double z_bottom_mm = 0.0, z_top_mm = 0.0;
  std::vector<Polygon2> as_cut, planned;
};

struct PieceInSheet {
  const CutPiece* piece;
  ClipperLib::Paths paths;
  Box box;
  double area_mm2;
};

// The pieces of one section that belong to a placement (more than match_share of their area in
// its planned section), in the layer's frame; appended to `out`. False when none is.
bool take_part_pieces(const std::vector<PieceInSheet>& pieces, const std::vector<Polygon2>& planned_layer,
                      const Placement& pl, double share, std::vector<Polygon2>& out) {
  std::vector<Polygon2> planned_sheet;
  Box box;
  for (const auto& ring : planned_layer) {
    planned_sheet.push_back(to_sheet(ring, pl));
    box.add(planned_sheet.back());
  }
  const ClipperLib::Paths planned = gd::to_clipper(planned_sheet);
  bool any = false;
  for (const PieceInSheet& p : pieces) {
    if (!(p.area_mm2 > 0.0) || !p.box.meets(box)) continue;
    if (intersection_mm2(p.paths, planned) <= share * p.area_mm2) continue;
    for (const auto& ring : p.piece->rings) out.push_back(to_layer(ring, pl));
    any = true;
  }
  return any;
}

std::vector<PieceInSheet> pieces_of(const CutSection& section) {
  std::vector<PieceInSheet> out;
  for (const CutPiece& piece : section.pieces) {
    PieceInSheet p{&piece, gd::to_clipper(piece.rings), {}, 0.0};
    for (const auto& ring : piece.rings) p.box.add(ring);
    p.area_mm2 = gd::area_mm2(p.paths);
    out.push_back(std::move(p));
  }
  return out;
}

std::expected<void, Error> check_sheets(std::span<const NestedSheet> sheets, std::span<const CutSheet> cut) {
  for (const NestedSheet& s : sheets) {
    const auto n = std::count_if(cut.begin(), cut.end(), [&](const CutSheet& c) { return c.sheet == s.index; });
    if (n != 1) return bad(fmt::format("as-cut: sheet {} is {} (every sheet of the nest once)", s.index, n == 0 ? "not measured" : "measured twice"));
  }
  for (const CutSheet& c : cut) {
    const auto s = std::find_if(sheets.begin(), sheets.end(), [&](const NestedSheet& n) { return n.index == c.sheet; });
    if (s == sheets.end()) return bad(fmt::format("as-cut: sheet {} is not in the nest", c.sheet));
    if (std::abs(s->thickness_mm - c.thickness_mm) > 1e-6)
      return bad(fmt::format("as-cut: sheet {} was cut {} mm thick, the plan's is {} mm", c.sheet, c.thickness_mm, s->thickness_mm));
    double last = 0.0;
    for (const CutSection& section : c.sections) {
      if (!(section.depth_mm > last) || !(section.depth_mm < c.thickness_mm))
        return bad(fmt::format("as-cut: sheet {} has a section at depth {} mm (need increasing depths inside its {} mm)", c.sheet,
                               section.depth_mm, c.thickness_mm));
      last = section.depth_mm;
    }
    if (c.sections.empty()) return bad(fmt::format("as-cut: sheet {} has no section", c.sheet));
  }
  return {};
}

}  // namespace

namespace {

// What build_slabs gathers per layer: its sheet's depths, and per depth the rings of its parts'
// pieces in the layer's frame.
struct LayerGather {
  std::vector<double> depths_mm;
  std::vector<std::vector<Polygon2>> as_cut;
  int parts = 0, freed = 0;
};

std::expected<void, Error> gather_sheet(const BevelPlan& plan, std::span<const Part> parts, const NestedSheet& sheet,
                                        const CutSheet& cut, double share, std::map<std::size_t, LayerGather>& layers,
                                        std::vector<std::string>& not_freed) {
  std::vector<std::vector<PieceInSheet>> pieces;
  std::vector<double> depths;
  for (const CutSection& section : cut.sections) {
    pieces.push_back(pieces_of(section));
    depths.push_back(section.depth_mm);
  }
  for (const Placement& pl : sheet.placements) {
    if (pl.part < 0 || static_cast<std::size_t>(pl.part) >= parts.size())
      return bad(fmt::format("as-cut: sheet {} places part {}, not one of the {} parts", sheet.index, pl.part, parts.size()));
    const Part& part = parts[static_cast<std::size_t>(pl.part)];
    if (part.layer_slot < 0 || static_cast<std::size_t>(part.layer_slot) >= plan.layers.size())
      return bad(fmt::format("as-cut: part L{}-{} has layer slot {}, not in the plan", part.layer, part.island, part.layer_slot));
    const auto slot = static_cast<std::size_t>(part.layer_slot);
    const LayerPlan& layer = plan.layers[slot];
    LayerGather& g = layers[slot];
    if (g.depths_mm.empty()) {
      g.depths_mm = depths;
      g.as_cut.resize(depths.size());
    } else if (g.depths_mm != depths) {
      return bad(fmt::format("as-cut: layer {} lies on sheets sectioned at different depths", layer.index));
    }
    std::vector<int> outlines{part.outer};
    outlines.insert(outlines.end(), part.holes.begin(), part.holes.end());
    bool freed = true;
    for (std::size_t k = 0; k < depths.size(); ++k) {
      const auto planned = layer_section(layer, layer.z_top_mm() - depths[k], outlines);
      if (take_part_pieces(pieces[k], planned, pl, share, g.as_cut[k]) || !freed) continue;
      not_freed.push_back(fmt::format("L{}-{} on sheet {} at {:.3g} mm", part.layer, part.island, sheet.index, depths[k]));
      freed = false;
    }
    ++g.parts;
    g.freed += freed ? 1 : 0;
  }
  return {};
}

std::vector<Polygon2> united(const std::vector<Polygon2>& rings) {
  ClipperLib::Clipper c;
  c.AddPaths(gd::to_clipper(rings), ClipperLib::ptSubject, true);
  ClipperLib::Paths out;
  c.Execute(ClipperLib::ctUnion, out, ClipperLib::pftNonZero, ClipperLib::pftNonZero);
  return gd::from_clipper(out);
}

// Each depth stands for the slab from halfway to the depth above (the top face for the first) to
// halfway to the one below (the bottom face for the last).
std::vector<Slab> slabs_of(const BevelPlan& plan, std::size_t slot, const LayerGather& g) {
  const LayerPlan& layer = plan.layers[slot];
  std::vector<Slab> out;
  const std::size_t n = g.depths_mm.size();
  for (std::size_t k = 0; k < n; ++k) {
    const double from = k == 0 ? 0.0 : 0.5 * (g.depths_mm[k - 1] + g.depths_mm[k]);
    const double to = k + 1 == n ? layer.thickness_mm : 0.5 * (g.depths_mm[k] + g.depths_mm[k + 1]);
    const double z = layer.z_top_mm() - g.depths_mm[k];
    out.push_back({slot, z, to - from, layer.z_top_mm() - to, layer.z_top_mm() - from, united(g.as_cut[k]), layer_section(layer, z)});
  }
  return out;
}

struct Farthest {
  double mm = 0.0;
  Eigen::Vector3d at = Eigen::Vector3d::Zero();
};

struct SlabMeasure {
  double model_mm2 = 0.0, as_cut_xor_mm2 = 0.0, planned_xor_mm2 = 0.0;
  Farthest as_cut_max, planned_max;
};

double xor_mm2(const ClipperLib::Paths& model, double model_mm2, const std::vector<Polygon2>& section) {
  const ClipperLib::Paths s = gd::to_clipper(section);
  const double common = model.empty() || s.empty() ? 0.0 : intersection_mm2(model, s);
  return std::max(0.0, model_mm2 + gd::area_mm2(s) - 2.0 * common);
}

// The largest distance from the section's boundary (points every `step` along it, at height z)
// to the model's surface.
Farthest wall_max_mm(const std::vector<Polygon2>& section, double z, double step, const gd::TriangleTree& tree) {
  Farthest worst;
  std::int32_t hint = -1;
  for (const Polygon2& ring : section)
    for (std::size_t i = 0; i < ring.size(); ++i) {
      const Eigen::Vector2d a = ring[i], b = ring[(i + 1) % ring.size()];
      const int n = std::max(1, static_cast<int>(std::ceil((b - a).norm() / step)));
      for (int j = 0; j < n; ++j) {
        const Eigen::Vector2d p = a + (b - a) * (static_cast<double>(j) / n);
        const Eigen::Vector3d q(p.x(), p.y(), z);
        if (const double d = tree.distance(q, worst.mm, hint); d > worst.mm) worst = {d, q};
      }
    }
  return worst;
}

SlabMeasure measure_slab(const Slab& slab, const Slice& slice, const gd::TriangleTree& tree, double step) {
  ClipperLib::Paths model;
  for (const auto& loop : slice.loops) model.push_back(gd::to_clipper(loop.points));
  ClipperLib::Clipper c;
  c.AddPaths(model, ClipperLib::ptSubject, true);
  ClipperLib::Paths clean;
  c.Execute(ClipperLib::ctUnion, clean, ClipperLib::pftPositive, ClipperLib::pftPositive);
  SlabMeasure m;
  m.model_mm2 = gd::area_mm2(clean);
  m.as_cut_xor_mm2 = xor_mm2(clean, m.model_mm2, slab.as_cut);
  m.planned_xor_mm2 = xor_mm2(clean, m.model_mm2, slab.planned);
  m.as_cut_max = wall_max_mm(slab.as_cut, slab.z_mm, step, tree);
  m.planned_max = wall_max_mm(slab.planned, slab.z_mm, step, tree);
  return m;
}

void add_slab(VolumeAndDistance& to, double& model_to, const Slab& slab, const SlabMeasure& m, bool as_cut) {
  to.volume_mm3 += (as_cut ? m.as_cut_xor_mm2 : m.planned_xor_mm2) * slab.height_mm;
  const Farthest& far = as_cut ? m.as_cut_max : m.planned_max;
  if (far.mm > to.max_mm) {
    to.max_mm = far.mm;
    to.max_at_mm = far.at;
  }
  if (as_cut) model_to += m.model_mm2 * slab.height_mm;
}

void finish(VolumeAndDistance& v, double model_mm3) { v.volume_pct = model_mm3 > 0.0 ? 100.0 * v.volume_mm3 / model_mm3 : 0.0; }

}  // namespace

std::expected<AsCutDeviation, Error> measure_as_cut(const Mesh& mesh, const BevelPlan& plan, std::span<const Part> parts,
                                                    std::span<const NestedSheet> sheets, std::span<const CutSheet> cut,
                                                    const AsCutParams& params) {
  if (!(params.wall_sample_mm > 0.0) || !(params.match_share > 0.0 && params.match_share < 1.0))
    return bad(fmt::format("as-cut: wall_sample_mm > 0 and match_share in (0, 1) (got {}, {})", params.wall_sample_mm, params.match_share));
  if (mesh.faces.empty()) return std::unexpected(Error{ErrorCode::empty_mesh, "as-cut: the mesh has no facet"});
  if (auto ok = check_sheets(sheets, cut); !ok) return std::unexpected(ok.error());
  AsCutDeviation d;
  std::map<std::size_t, LayerGather> layers;
  for (const NestedSheet& s : sheets) {
    const CutSheet& c = *std::find_if(cut.begin(), cut.end(), [&](const CutSheet& x) { return x.sheet == s.index; });
    if (auto ok = gather_sheet(plan, parts, s, c, params.match_share, layers, d.not_freed); !ok) return std::unexpected(ok.error());
  }
  std::vector<Slab> slabs;
  for (const auto& [slot, g] : layers)
    for (Slab& s : slabs_of(plan, slot, g)) slabs.push_back(std::move(s));
  std::vector<double> zs;
  for (const Slab& s : slabs) zs.push_back(s.z_mm);
  SliceParams slice_params;
  slice_params.parallel = params.parallel;
  auto slices = slice_mesh(mesh, zs, slice_params);
  if (!slices) return std::unexpected(slices.error());
  const gd::TriangleTree tree(mesh.vertices, mesh.faces, gd::threads_for(params.parallel));
  std::vector<SlabMeasure> measures(slabs.size());
  auto one = [&](std::size_t i) { measures[i] = measure_slab(slabs[i], (*slices)[i], tree, params.wall_sample_mm); };
  if (params.parallel)
    tbb::parallel_for(std::size_t{0}, slabs.size(), one);
  else
    for (std::size_t i = 0; i < slabs.size(); ++i) one(i);
  // Summed in slab order: the totals do not depend on threads.
  std::map<std::size_t, LayerAsCut> by_layer;
  for (std::size_t i = 0; i < slabs.size(); ++i) {
    d.slabs.push_back({plan.layers[slabs[i].layer_slot].index, slabs[i].z_bottom_mm, slabs[i].z_top_mm, slabs[i].as_cut});
    LayerAsCut& l = by_layer[slabs[i].layer_slot];
    add_slab(l.as_cut, l.model_volume_mm3, slabs[i], measures[i], true);
    double unused = 0.0;
    add_slab(l.planned, unused, slabs[i], measures[i], false);
  }
  for (auto& [slot, l] : by_layer) {
    l.layer = plan.layers[slot].index;
    l.parts = layers[slot].parts;
    l.parts_freed = layers[slot].freed;
    finish(l.as_cut, l.model_volume_mm3);
    finish(l.planned, l.model_volume_mm3);
    for (auto [total, part] : {std::pair{&d.as_cut, &l.as_cut}, std::pair{&d.planned, &l.planned}}) {
      total->volume_mm3 += part->volume_mm3;
      if (part->max_mm > total->max_mm) {
        total->max_mm = part->max_mm;
        total->max_at_mm = part->max_at_mm;
      }
    }
    d.model_volume_mm3 += l.model_volume_mm3;
    d.parts += l.parts;
    d.parts_freed += l.parts_freed;
    d.layers.push_back(l);
  }
  finish(d.as_cut, d.model_volume_mm3);
  finish(d.planned, d.model_volume_mm3);
  return d;
}

}  // namespace lamina
