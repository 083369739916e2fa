#pragma once
// The part as the machine really cut it (issue 20): the pieces a cut sheet fell into (sections at
// several depths in the sheet frame, as lamina-sim --as-cut writes them, read at the CLI's edge)
// mapped back through the nest's placements onto the CAD model, and measured beside the plan.
//
// Both the as-cut and the planned part are measured the same way, so the two numbers compare:
// - volume: per layer, the sheet's depths stand for equal slabs of it; each slab's section
//   against the model's slice at the slab's middle, |A xor M| = |A| + |M| − 2|A ∩ M|, times the
//   slab's height. The planned section is layer_section at the same heights.
// - largest distance: from points of the cut wall (the sections' boundaries, every
//   `wall_sample_mm`) to the model's surface, the way a probe on the finished part is compared
//   with the CAD. One way: wall to model.
// Layer faces are the sheet's own faces, the same as cut and as planned; the model above the top
// layer or below the bottom one is outside both and not counted.
#include "lamina/core/bevel.hpp"
#include "lamina/core/error.hpp"
#include "lamina/core/mesh.hpp"
#include "lamina/core/nest.hpp"
#include "lamina/core/parts.hpp"
#include "lamina/core/polygon.hpp"
#include "lamina/core/triangle_soup.hpp"

#include <Eigen/Core>

#include <expected>
#include <span>
#include <string>
#include <vector>

namespace lamina {

struct CutPiece {
  std::vector<Polygon2> rings;  // sheet frame: the outer ring (CCW) first, then its holes (CW)
};

struct CutSection {
  double depth_mm = 0.0;  // below the sheet's top face
  std::vector<CutPiece> pieces;
};

struct CutSheet {
  int sheet = 0;  // NestedSheet::index
  double thickness_mm = 0.0;
  std::vector<CutSection> sections;  // by depth, increasing
};

struct AsCutParams {
  double wall_sample_mm = 0.5;
  // A piece is a part's when more than this share of its area lies in the part's planned section:
  // slugs (inside holes) and the skeleton have almost none.
  double match_share = 0.5;
  bool parallel = true;
};

struct VolumeAndDistance {
  double volume_mm3 = 0.0;  // symmetric difference with the model
  double volume_pct = 0.0;  // of the model's volume in the same slabs
  double max_mm = 0.0;      // largest distance from the wall to the model's surface
  Eigen::Vector3d max_at_mm = Eigen::Vector3d::Zero();  // where on the wall (build frame)
};

struct LayerAsCut {
  int layer = 0;  // LayerPlan::index
  double model_volume_mm3 = 0.0;
  VolumeAndDistance planned, as_cut;
  int parts = 0, parts_freed = 0;  // a part not freed: no piece of it at some depth (a microjoint, a cut that did not go through)
};

// One slab of a layer as cut: the parts' pieces at one depth, mapped into the build frame.
struct AsCutSlab {
  int layer = 0;                              // LayerPlan::index
  double z_bottom_mm = 0.0, z_top_mm = 0.0;   // the depth stands for this much of the layer
  std::vector<Polygon2> rings;                // build frame: outers counter-clockwise, holes clockwise
};

struct AsCutDeviation {
  std::vector<LayerAsCut> layers;  // every layer with a sheet measured, in plan order
  std::vector<AsCutSlab> slabs;    // what was measured, layer by layer, top down
  double model_volume_mm3 = 0.0;
  VolumeAndDistance planned, as_cut;
  int parts = 0, parts_freed = 0;
  std::vector<std::string> not_freed;  // "L3-1 on sheet 2 at 7.5 mm"
};

// Errors (invalid_argument): a sheet that is not in the nest or measured twice, a thickness
// that differs from the sheet's, a depth outside the sheet, a part whose layer the plan lacks.
std::expected<AsCutDeviation, Error> measure_as_cut(const Mesh& mesh, const BevelPlan& plan,
                                                    std::span<const Part> parts,
                                                    std::span<const NestedSheet> sheets,
                                                    std::span<const CutSheet> cut, const AsCutParams& params);

// The parts as cut as a triangle mesh in the build frame, to load beside the model and the
// planned stack: every slab a closed prism of its rings (walls, and caps on exactly the ring
// vertices), stepped from slab to slab as the sections are.
TriangleSoup as_cut_mesh(std::span<const AsCutSlab> slabs);

}  // namespace lamina
