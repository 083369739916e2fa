#pragma once
// Bevel plans built by hand for the deviation and stack-mesh tests (no plan_bevels involved), and
// the exact volumes of the faceted solids they describe.
#include <lamina/core/bevel.hpp>
#include <lamina/core/polygon.hpp>
#include <lamina/core/triangle_soup.hpp>

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <functional>
#include <numbers>
#include <utility>
#include <vector>

namespace lamina::dev_test {

// A jet line of one pass at one station: offsets along the station normal at the layer's
// bottom and top faces.
struct Offsets {
  double bottom = 0.0;
  double top = 0.0;
};

// An outline from base points and outward normals; pass p's line at station s is
// lines(p, s). Top/bottom points are base + u·n at the layer's faces.
inline LayerOutline make_outline(const std::vector<Eigen::Vector2d>& base, const std::vector<Eigen::Vector2d>& normals,
                                 int passes, const std::function<Offsets(int, std::size_t)>& lines, double z_bottom,
                                 double z_top, bool hole = false, int parent = -1) {
  LayerOutline o;
  o.is_hole = hole;
  o.parent = parent;
  for (std::size_t s = 0; s < base.size(); ++s) {
    CutStation st;
    st.base_mm = base[s];
    st.normal = normals[s];
    o.stations.push_back(st);
  }
  for (int p = 0; p < passes; ++p) {
    CutPass pass;
    for (std::size_t s = 0; s < base.size(); ++s) {
      const Offsets u = lines(p, s);
      CutLine line;
      const Eigen::Vector2d top = base[s] + u.top * normals[s];
      const Eigen::Vector2d bottom = base[s] + u.bottom * normals[s];
      line.top_mm = Eigen::Vector3d(top.x(), top.y(), z_top);
      line.bottom_mm = Eigen::Vector3d(bottom.x(), bottom.y(), z_bottom);
      line.tool_axis = (line.top_mm - line.bottom_mm).normalized();
      line.paper_v = Eigen::Vector3d::Zero();
      pass.lines.push_back(line);
    }
    o.passes.push_back(pass);
  }
  return o;
}

// A circle of n stations at radius r (angles 2πj/n from +x, as the test shapes' meridians);
// counter-clockwise with outward normals for an outer, clockwise with normals towards the axis
// (out of the material) for a hole. Pass p at every station runs from radius
// radii[p].first (bottom) to radii[p].second (top).
inline LayerOutline circle_outline(double r, int n, const std::vector<std::pair<double, double>>& radii, double z_bottom,
                                   double z_top, bool hole = false, int parent = -1, Eigen::Vector2d centre = {0, 0}) {
  std::vector<Eigen::Vector2d> base, normals;
  for (int j = 0; j < n; ++j) {
    const double phi = 2.0 * std::numbers::pi * (hole ? (n - j) % n : j) / n;
    const Eigen::Vector2d radial(std::cos(phi), std::sin(phi));
    base.push_back(centre + r * radial);
    normals.push_back(hole ? Eigen::Vector2d(-radial) : radial);
  }
  const double sign = hole ? -1.0 : 1.0;
  return make_outline(
      base, normals, static_cast<int>(radii.size()),
      [&](int p, std::size_t) {
        const auto& [rb, rt] = radii[static_cast<std::size_t>(p)];
        return Offsets{sign * (rb - r), sign * (rt - r)};
      },
      z_bottom, z_top, hole, parent);
}

inline LayerPlan make_layer(int index, double z_bottom, double thickness, std::vector<LayerOutline> outlines,
                            std::vector<double> sub_slices = {}) {
  LayerPlan layer;
  layer.index = index;
  layer.z_bottom_mm = z_bottom;
  layer.thickness_mm = thickness;
  layer.outlines = std::move(outlines);
  layer.sub_slice_z_mm = std::move(sub_slices);
  int passes = 0;
  for (const auto& o : layer.outlines) passes = std::max(passes, static_cast<int>(o.passes.size()));
  layer.passes = passes;
  return layer;
}

// One vertical-walled disc layer of radius r with n stations.
inline LayerPlan disc_layer(int index, double z_bottom, double thickness, double r, int n) {
  return make_layer(index, z_bottom, thickness, {circle_outline(r, n, {{r, r}}, z_bottom, z_bottom + thickness)});
}

// Volume of a frustum whose sections are regular n-gons of circumradius r0 (bottom) to r1 (top).
inline double ngon_frustum_volume(int n, double r0, double r1, double h) {
  return 0.5 * n * std::sin(2.0 * std::numbers::pi / n) * h * (r0 * r0 + r0 * r1 + r1 * r1) / 3.0;
}

// A closed frustum soup about z: radius r0 at z = 0, r1 at z = h, `segments` meridians at
// 2πj/segments, cap fans about the axis, outward winding.
inline TriangleSoup frustum(double r0, double r1, double h, int segments) {
  auto p = [&](int j, double r, double z) {
    const double phi = 2.0 * std::numbers::pi * (j % segments) / segments;
    return Eigen::Vector3f(static_cast<float>(r * std::cos(phi)), static_cast<float>(r * std::sin(phi)),
                           static_cast<float>(z));
  };
  TriangleSoup s;
  s.format = "test:frustum";
  auto tri = [&](const Eigen::Vector3f& a, const Eigen::Vector3f& b, const Eigen::Vector3f& c) {
    s.corners.push_back(a);
    s.corners.push_back(b);
    s.corners.push_back(c);
  };
  const Eigen::Vector3f bottom(0, 0, 0), top(0, 0, static_cast<float>(h));
  for (int j = 0; j < segments; ++j) {
    tri(p(j, r0, 0), p(j + 1, r0, 0), p(j + 1, r1, h));
    tri(p(j, r0, 0), p(j + 1, r1, h), p(j, r1, h));
    tri(top, p(j, r1, h), p(j + 1, r1, h));
    tri(bottom, p(j + 1, r0, 0), p(j, r0, 0));
  }
  return s;
}

// An axis-aligned square outline of half-width `half` about `centre` with vertical walls:
// stations at the corners (diagonal normals) and mid-edges, CCW with outward normals, or for a
// hole CW with normals into the hole.
inline LayerOutline square_outline(Eigen::Vector2d centre, double half, double z_bottom, double z_top, bool hole = false,
                                   int parent = -1) {
  std::vector<Eigen::Vector2d> base, normals;
  const Eigen::Vector2d corners[4] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
  for (int k = 0; k < 4; ++k) {
    const Eigen::Vector2d a = corners[k], b = corners[(k + 1) % 4];
    base.push_back(centre + half * a);
    normals.push_back(a.normalized());
    base.push_back(centre + half * 0.5 * (a + b));
    normals.push_back(Eigen::Vector2d((b - a).y(), -(b - a).x()).normalized());
  }
  if (hole) {
    std::reverse(base.begin(), base.end());
    std::reverse(normals.begin(), normals.end());
    for (auto& n : normals) n = -n;
  }
  return make_outline(base, normals, 1, [](int, std::size_t) { return Offsets{0, 0}; }, z_bottom, z_top, hole, parent);
}

// n stations on a circle of radius r about the origin (angles 2πj/n), CCW, and their outward normals.
inline std::pair<std::vector<Eigen::Vector2d>, std::vector<Eigen::Vector2d>> circle_stations(double r, int n) {
  std::vector<Eigen::Vector2d> base, normals;
  for (int j = 0; j < n; ++j) {
    const Eigen::Vector2d u(std::cos(2.0 * std::numbers::pi * j / n), std::sin(2.0 * std::numbers::pi * j / n));
    base.push_back(r * u);
    normals.push_back(u);
  }
  return {base, normals};
}

}  // namespace lamina::dev_test
