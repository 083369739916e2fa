#pragma once
// Axis-aligned boxes as triangle soups, wound outward, for tests that need exact answers.
#include "lamina/core/triangle_soup.hpp"

#include <array>

namespace lamina::test {

inline void append_box(TriangleSoup& soup, const Eigen::Vector3f& lo, const Eigen::Vector3f& hi) {
  auto v = [&](int i, int j, int k) {
    return Eigen::Vector3f(i ? hi.x() : lo.x(), j ? hi.y() : lo.y(), k ? hi.z() : lo.z());
  };
  // Corner codes ijk; each face as two triangles, counter-clockwise seen from outside.
  static constexpr std::array<std::array<int, 3>, 12> tris{{
      {0b000, 0b010, 0b110}, {0b000, 0b110, 0b100},  // bottom, -z
      {0b001, 0b101, 0b111}, {0b001, 0b111, 0b011},  // top, +z
      {0b000, 0b100, 0b101}, {0b000, 0b101, 0b001},  // front, -y
      {0b010, 0b011, 0b111}, {0b010, 0b111, 0b110},  // back, +y
      {0b000, 0b001, 0b011}, {0b000, 0b011, 0b010},  // left, -x
      {0b100, 0b110, 0b111}, {0b100, 0b111, 0b101},  // right, +x
  }};
  for (const auto& t : tris)
    for (int c : t) soup.corners.push_back(v((c >> 2) & 1, (c >> 1) & 1, c & 1));
}

inline TriangleSoup box(const Eigen::Vector3f& lo, const Eigen::Vector3f& hi) {
  TriangleSoup s;
  s.format = "test";
  append_box(s, lo, hi);
  return s;
}

// A box whose triangles are all reversed (an inverted shell: a cavity when nested in another).
inline void append_inverted_box(TriangleSoup& soup, const Eigen::Vector3f& lo, const Eigen::Vector3f& hi) {
  TriangleSoup b = box(lo, hi);
  for (std::size_t t = 0; t < b.corners.size(); t += 3) std::swap(b.corners[t + 1], b.corners[t + 2]);
  soup.corners.insert(soup.corners.end(), b.corners.begin(), b.corners.end());
}

}  // namespace lamina::test
