#pragma once
// Checks shared by the bevel tests: uniform layers, and "no cut removes part material" by
// sampling points along every cut line and testing them against the model's sections.
#include "lamina/core/bevel.hpp"
#include "lamina/core/deviation.hpp"
#include "lamina/core/section_lines.hpp"
#include "lamina/core/slice.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
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

// Part material the cuts take (issue 17, item 1), checked between stations too: points along the
// model's section boundary (every `spacing_mm`) at `heights_per_layer` heights of each layer must
// lie inside the layer's section (layer_section: the chords of the cut lines) or within tol_mm
// of its boundary. The deepest point outside, and where.
struct Gouge {
  double depth_mm = 0.0;
  std::string where;
};

inline double distance_to_rings(const Eigen::Vector2d& q, const std::vector<Polygon2>& rings) {
  double best = std::numeric_limits<double>::infinity();
  for (const auto& r : rings)
    for (std::size_t i = 0; i < r.size(); ++i) {
      const Eigen::Vector2d a = r[i], d = r[(i + 1) % r.size()] - a;
      const double s = d.squaredNorm() > 0 ? std::clamp((q - a).dot(d) / d.squaredNorm(), 0.0, 1.0) : 0.0;
      best = std::min(best, (a + s * d - q).norm());
    }
  return best;
}

// Winding number of the rings around q (outer rings CCW count +1, holes CW −1).
inline int winding(const Eigen::Vector2d& q, const std::vector<Polygon2>& rings) {
  int w = 0;
  for (const auto& r : rings)
    for (std::size_t i = 0; i < r.size(); ++i) {
      const Eigen::Vector2d a = r[i], b = r[(i + 1) % r.size()];
      const double cross = (b.x() - a.x()) * (q.y() - a.y()) - (q.x() - a.x()) * (b.y() - a.y());
      if (a.y() <= q.y() && b.y() > q.y() && cross > 0) ++w;
      if (a.y() > q.y() && b.y() <= q.y() && cross < 0) --w;
    }
  return w;
}

inline Gouge deepest_gouge(const Mesh& mesh, const BevelPlan& plan, int heights_per_layer = 21,
                           double spacing_mm = 0.02) {
  Gouge g;
  for (const auto& layer : plan.layers) {
    std::vector<double> zs;
    const double nudge = std::min(2e-3, 0.05 * layer.thickness_mm);
    for (int k = 0; k < heights_per_layer; ++k)
      zs.push_back(layer.z_bottom_mm + nudge + (layer.thickness_mm - 2 * nudge) * k / (heights_per_layer - 1));
    auto slices = slice_mesh(mesh, zs, SliceParams{});
    if (!slices) return g;
    for (std::size_t k = 0; k < zs.size(); ++k) {
      const std::vector<Polygon2> stack = layer_section(layer, zs[k]);
      for (const Loop& loop : (*slices)[k].loops) {
        const std::size_t n = loop.points.size();
        for (std::size_t i = 0; i < n; ++i) {
          const Eigen::Vector2d a = loop.points[i], d = loop.points[(i + 1) % n] - a;
          const int steps = std::max(1, static_cast<int>(std::ceil(d.norm() / spacing_mm)));
          for (int s = 0; s < steps; ++s) {
            const Eigen::Vector2d q = a + (static_cast<double>(s) / steps) * d;
            if (winding(q, stack) > 0) continue;
            const double depth = distance_to_rings(q, stack);
            if (depth > g.depth_mm) {
              g.depth_mm = depth;
              g.where = fmt::format("layer {} at ({:.3f}, {:.3f}, {:.3f})", layer.index, q.x(), q.y(), zs[k]);
            }
          }
        }
      }
    }
  }
  return g;
}

}  // namespace lamina::bevel_test
