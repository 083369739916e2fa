#pragma once
// Solids of revolution for tests: a closed profile in the (r, z) half-plane turned
// about the z axis. Profile points on the axis (r = 0) close the solid there without slivers.
#include "lamina/core/triangle_soup.hpp"

#include <Eigen/Core>

#include <cmath>
#include <utility>
#include <vector>

namespace lamina::test_shapes {

struct RZ {
  double r, z;
};

// profile: a closed polygon (last joins first), counter-clockwise in the (r, z) plane so the
// solid is wound outward.
inline TriangleSoup revolve(const std::vector<RZ>& profile, int segments) {
  TriangleSoup soup;
  soup.format = "test";
  auto at = [&](const RZ& p, int k) {
    const double phi = 2.0 * M_PI * (k % segments) / segments;
    return Eigen::Vector3f(static_cast<float>(p.r * std::cos(phi)), static_cast<float>(p.r * std::sin(phi)),
                           static_cast<float>(p.z));
  };
  auto tri = [&](const Eigen::Vector3f& a, const Eigen::Vector3f& b, const Eigen::Vector3f& c) {
    soup.corners.push_back(a);
    soup.corners.push_back(b);
    soup.corners.push_back(c);
  };
  const std::size_t n = profile.size();
  for (std::size_t i = 0; i < n; ++i) {
    const RZ& a = profile[i];
    const RZ& b = profile[(i + 1) % n];
    for (int k = 0; k < segments; ++k) {
      // Quad a(k), a(k+1), b(k+1), b(k): wound outward for a CCW (r, z) profile.
      const auto a0 = at(a, k), a1 = at(a, k + 1), b0 = at(b, k), b1 = at(b, k + 1);
      if (a.r == 0.0 && b.r == 0.0) continue;
      if (a.r == 0.0) {
        tri(a0, b1, b0);
      } else if (b.r == 0.0) {
        tri(a0, a1, b0);
      } else {
        tri(a0, b1, b0);
        tri(a0, a1, b1);
      }
    }
  }
  return soup;
}

}  // namespace lamina::test_shapes
