#pragma once
// Checks shared by the bevel tests: uniform layers, and "no cut removes part material" by
// sampling points along every cut line and testing them against the model's sections.
#include "lamina/core/bevel.hpp"
#include "lamina/core/section_lines.hpp"
#include "lamina/core/slice.hpp"

#include <fmt/format.h>

#include <cmath>
#include <string>
#include <vector>

namespace lamina::bevel_test {

inline std::vector<LayerSpan> uniform_layers(double height_mm, double thickness_mm) {
  std::vector<LayerSpan> layers;
  for (double z = 0; z < height_mm - 1e-9; z += thickness_mm) layers.push_back({z, thickness_mm, 0.0, true});
  return layers;
}

struct RemovalReport {
  std::size_t points = 0;
  std::size_t inside = 0;
  std::string first;  // where the first offending point is
};

// A point on a cut line lies in the part when, moved `tol_mm` further out of the part along the
// station normal, it is still inside the model's section at its height.
inline RemovalReport material_removed(const Mesh& mesh, const BevelPlan& plan, double tol_mm, int heights_per_layer = 5) {
  RemovalReport r;
  for (const auto& layer : plan.layers) {
    std::vector<double> zs;
    const double nudge = std::min(2e-3, 0.05 * layer.thickness_mm);
    for (int k = 0; k < heights_per_layer; ++k) {
      zs.push_back(layer.z_bottom_mm + nudge + (layer.thickness_mm - 2 * nudge) * k / (heights_per_layer - 1));
    }
    auto slices = slice_mesh(mesh, zs, SliceParams{});
    if (!slices) return r;
    std::vector<SectionLines> sections;
    for (const auto& s : *slices) sections.emplace_back(mesh, s);
    for (const auto& outline : layer.outlines) {
      for (std::size_t p = 0; p < outline.passes.size(); ++p) {
        const auto& pass = outline.passes[p];
        for (std::size_t i = 0; i < pass.lines.size(); ++i) {
          const auto& line = pass.lines[i];
          const auto& n = outline.stations[i].normal;
          for (std::size_t k = 0; k < zs.size(); ++k) {
            const double t = (zs[k] - layer.z_bottom_mm) / layer.thickness_mm;
            const Eigen::Vector3d q = line.bottom_mm + t * (line.top_mm - line.bottom_mm);
            const Eigen::Vector2d probe = q.head<2>() + tol_mm * n;
            ++r.points;
            if (sections[k].contains(probe)) {
              if (r.inside++ == 0) {
                r.first = fmt::format("layer {} outline {} pass {} station {} at ({:.4f}, {:.4f}, {:.4f})", layer.index,
                                      &outline - layer.outlines.data(), p, i, q.x(), q.y(), q.z());
              }
            }
          }
        }
      }
    }
  }
  return r;
}

}  // namespace lamina::bevel_test
