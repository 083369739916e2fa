#include "bevel/bevel_distance.hpp"

#include "geometry/clipper_bridge.hpp"
#include "deviation/surface_distance.hpp"

#include "lamina/core/deviation.hpp"

#include <algorithm>
#include <cmath>

namespace lamina::bevel_detail {
using geometry_detail::build_stack_shells;
using geometry_detail::StackShells;
using geometry_detail::Threads;
using geometry_detail::TriangleTree;
using deviation_detail::max_distance;
using deviation_detail::sample_region;
using geometry_detail::sort_morton;
using geometry_detail::to_clipper;
using deviation_detail::wall_samples;
namespace {

// The model's contours on the sub-slices: every vertex (sharp corners are vertices) and points
// at most ds apart between them.
std::vector<Eigen::Vector3d> contour_samples(const std::vector<const Slice*>& sub_slices, double ds) {
  std::vector<Eigen::Vector3d> out;
  for (const Slice* s : sub_slices)
    for (const Loop& l : s->loops) {
      const std::size_t n = l.size();
      for (std::size_t i = 0; i < n; ++i) {
        const Eigen::Vector2d& a = l.points[i];
        const Eigen::Vector2d& b = l.points[(i + 1) % n];
        const int pieces = static_cast<int>(std::clamp(std::ceil((b - a).norm() / ds), 1.0, 1e5));
        for (int k = 0; k < pieces; ++k) {
          const Eigen::Vector2d p = a + (b - a) * (static_cast<double>(k) / pieces);
          out.emplace_back(p.x(), p.y(), s->z_mm);
        }
      }
    }
  return out;
}

// Where a face of the layer holds material the model has not at that height (the layer's section
// less the model's sub-slice next to the face): excess, whose distance to the model is real. The
// rest of a face lies inside the model, where a neighbouring layer or the model's own material
// goes on: no surface of the part.
void exposed_face_samples(const LayerPlan& layer, double z_face, const Slice& model_next_to_face, double ds,
                          std::vector<Eigen::Vector3d>& out) {
  ClipperLib::Paths face = to_clipper(layer_section(layer, z_face));
  if (face.empty()) return;
  std::vector<Polygon2> model_rings;
  for (const Loop& l : model_next_to_face.loops) model_rings.push_back(l.points);
  ClipperLib::Clipper c;
  c.AddPaths(face, ClipperLib::ptSubject, true);
  ClipperLib::Paths model = to_clipper(model_rings);
  if (!model.empty()) c.AddPaths(model, ClipperLib::ptClip, true);
  ClipperLib::Paths excess;
  c.Execute(ClipperLib::ctDifference, excess, ClipperLib::pftPositive, ClipperLib::pftNonZero);
  constexpr double kRegionBudget = 20000.0;
  sample_region(excess, z_face, ds, kRegionBudget, out);
}

}  // namespace

double layer_surface_distance(const TriangleTree& model, double model_z_lo_mm, double model_z_hi_mm,
                              const LayerPlan& layer, const std::vector<const Slice*>& sub_slices, double ds_mm) {
  if (layer.outlines.empty()) return 0.0;
  std::vector<Eigen::Vector3d> walls;
  wall_samples(layer, ds_mm, walls);
  constexpr double kOnFace = 1e-6;
  if (!sub_slices.empty()) {
    exposed_face_samples(layer, layer.z_bottom_mm, *sub_slices.front(), ds_mm, walls);
    exposed_face_samples(layer, layer.z_top_mm(), *sub_slices.back(), ds_mm, walls);
  }
  std::erase_if(walls, [&](const Eigen::Vector3d& p) {
    return p.z() > model_z_hi_mm + kOnFace || p.z() < model_z_lo_mm - kOnFace;
  });
  sort_morton(walls, Threads::one);
  const double stack_to_model = max_distance(model, walls, Threads::one).distance;

  BevelPlan one;
  one.layers.push_back(layer);
  const StackShells shells = build_stack_shells(one);
  if (shells.faces.empty()) return stack_to_model;
  const TriangleTree shell(shells.vertices, shells.faces, Threads::one);
  std::vector<Eigen::Vector3d> contours = contour_samples(sub_slices, ds_mm);
  sort_morton(contours, Threads::one);
  const double model_to_stack = max_distance(shell, contours, Threads::one).distance;
  return std::max(stack_to_model, model_to_stack);
}

}  // namespace lamina::bevel_detail
