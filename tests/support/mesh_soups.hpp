#pragma once
// Triangle soups built in code for the build_mesh tests: boxes, a UV sphere, a cylinder, and
// helpers that damage them (flip, drop, append, perturb). Every shape is wound counter-clockwise
// seen from outside unless a helper changes it.
#include "shapes.hpp"

#include <lamina/core/mesh.hpp>
#include <lamina/core/triangle_soup.hpp>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <array>
#include <cmath>
#include <cstddef>
#include <numbers>
#include <vector>

namespace lamina::mesh_test {

inline void add_tri(TriangleSoup& s, const Eigen::Vector3f& a, const Eigen::Vector3f& b, const Eigen::Vector3f& c) {
  s.corners.push_back(a);
  s.corners.push_back(b);
  s.corners.push_back(c);
}

inline void add_quad(TriangleSoup& s, const Eigen::Vector3f& a, const Eigen::Vector3f& b, const Eigen::Vector3f& c,
                     const Eigen::Vector3f& d) {
  add_tri(s, a, b, c);
  add_tri(s, a, c, d);
}

// Axis-aligned box, 12 facets, outward.
inline TriangleSoup box(const Eigen::Vector3f& lo, const Eigen::Vector3f& hi) {
  auto v = [&](int i) {
    return Eigen::Vector3f((i & 1) ? hi.x() : lo.x(), (i & 2) ? hi.y() : lo.y(), (i & 4) ? hi.z() : lo.z());
  };
  TriangleSoup s;
  s.format = "test";
  add_quad(s, v(0), v(2), v(3), v(1));  // -z
  add_quad(s, v(4), v(5), v(7), v(6));  // +z
  add_quad(s, v(0), v(1), v(5), v(4));  // -y
  add_quad(s, v(2), v(6), v(7), v(3));  // +y
  add_quad(s, v(0), v(4), v(6), v(2));  // -x
  add_quad(s, v(1), v(3), v(7), v(5));  // +x
  return s;
}

inline TriangleSoup unit_cube() { return box(Eigen::Vector3f::Zero(), Eigen::Vector3f::Ones()); }

inline TriangleSoup append(TriangleSoup a, const TriangleSoup& b) {
  a.corners.insert(a.corners.end(), b.corners.begin(), b.corners.end());
  return a;
}

// Reverse the winding of one facet.
inline void flip_facet(TriangleSoup& s, std::size_t f) { std::swap(s.corners[3 * f + 1], s.corners[3 * f + 2]); }

// Reverse every facet (inside out).
inline TriangleSoup inverted(TriangleSoup s) {
  for (std::size_t f = 0; f < s.triangle_count(); ++f) flip_facet(s, f);
  return s;
}

inline TriangleSoup without_facet(TriangleSoup s, std::size_t f) {
  s.corners.erase(s.corners.begin() + static_cast<std::ptrdiff_t>(3 * f),
                  s.corners.begin() + static_cast<std::ptrdiff_t>(3 * f + 3));
  return s;
}

// Move coordinates of every second corner by ±1e-12 where they are zero, and by one float step
// towards zero elsewhere (1e-12 is below float resolution at 1), so corners that should be one
// vertex are no longer bit-identical but stay within ~1e-7 of each other.
inline TriangleSoup perturbed(TriangleSoup s) {
  for (std::size_t c = 0; c < s.corners.size(); ++c) {
    if (c % 2 == 0) continue;
    for (int a = 0; a < 3; ++a) {
      float& x = s.corners[c][a];
      const bool odd = ((c / 2 + static_cast<std::size_t>(a)) % 2) == 1;
      if (x == 0.0f)
        x = odd ? 1e-12f : -1e-12f;
      else if (odd)
        x = std::nextafter(x, 0.0f);
    }
  }
  return s;
}

// UV sphere (tests/support/shapes.hpp) moved to centre c.
inline TriangleSoup uv_sphere(double r, int segments, int rings, const Eigen::Vector3d& c = Eigen::Vector3d::Zero()) {
  return test::translated(test::uv_sphere(r, segments, rings), c.cast<float>());
}

// Closed cylinder along z from 0 to h: side quads, cap fans about the axis.
inline TriangleSoup cylinder(double r, double h, int segments) {
  const double pi = std::numbers::pi;
  auto p = [&](int j, double z) {
    const double ph = 2.0 * pi * (j % segments) / segments;
    return Eigen::Vector3f(static_cast<float>(r * std::cos(ph)), static_cast<float>(r * std::sin(ph)),
                           static_cast<float>(z));
  };
  const Eigen::Vector3f bottom(0, 0, 0), top(0, 0, static_cast<float>(h));
  TriangleSoup s;
  s.format = "test";
  for (int j = 0; j < segments; ++j) {
    add_quad(s, p(j, 0), p(j + 1, 0), p(j + 1, h), p(j, h));
    add_tri(s, top, p(j, h), p(j + 1, h));
    add_tri(s, bottom, p(j + 1, 0), p(j, 0));
  }
  return s;
}

using test::soup_volume;

}  // namespace lamina::mesh_test
