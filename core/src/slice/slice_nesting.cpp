// Loop areas and the containment tree of a slice.
#include "slice/slice_internal.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace lamina::slice_detail {

void compute_area(Loop& loop) {
  const std::size_t n = loop.points.size();
  double twice = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector2d& a = loop.points[i];
    const Eigen::Vector2d& b = loop.points[(i + 1) % n];
    twice += a.x() * b.y() - a.y() * b.x();
  }
  loop.area_mm2 = 0.5 * twice;
}

int winding_number(const Loop& loop, const Eigen::Vector2d& p) {
  // Sunday's crossing rule: upward edges crossing the ray to the right of p count +1, downward -1.
  int w = 0;
  const std::size_t n = loop.points.size();
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector2d& a = loop.points[i];
    const Eigen::Vector2d& b = loop.points[(i + 1) % n];
    const double side = (b.x() - a.x()) * (p.y() - a.y()) - (p.x() - a.x()) * (b.y() - a.y());
    if (a.y() <= p.y()) {
      if (b.y() > p.y() && side > 0.0) ++w;
    } else if (b.y() <= p.y() && side < 0.0) {
      --w;
    }
  }
  return w;
}

namespace {

struct Box {
  Eigen::Vector2d lo, hi;
  bool contains(const Box& o) const {
    return lo.x() <= o.lo.x() && lo.y() <= o.lo.y() && hi.x() >= o.hi.x() && hi.y() >= o.hi.y();
  }
};

Box box_of(const Loop& l) {
  Box b{l.points.front(), l.points.front()};
  for (const auto& p : l.points) {
    b.lo = b.lo.cwiseMin(p);
    b.hi = b.hi.cwiseMax(p);
  }
  return b;
}

// A point strictly inside the loop's own region next to its longest vector: loops of a slice do
// not cross, so its containment by another loop is that of the whole loop, and it never sits on a
// shared vertex where touching loops meet.
Eigen::Vector2d probe_point(const Loop& l) {
  const std::size_t n = l.points.size();
  std::size_t best = 0;
  double best_len = -1.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double len = (l.points[(i + 1) % n] - l.points[i]).squaredNorm();
    if (len > best_len) {
      best_len = len;
      best = i;
    }
  }
  const Eigen::Vector2d a = l.points[best], b = l.points[(best + 1) % n];
  const Eigen::Vector2d mid = 0.5 * (a + b);
  // Left of the vector is the loop's own side for CCW and CW loops alike; step a hair into it.
  const Eigen::Vector2d left(-(b - a).y(), (b - a).x());
  return mid + 1e-7 * left;
}

}  // namespace

void compute_nesting(std::vector<Loop>& loops) {
  const std::size_t n = loops.size();
  if (n == 1) {
    loops[0].parent = -1;
    loops[0].depth = 0;
    return;
  }
  std::vector<Box> boxes(n);
  std::vector<Eigen::Vector2d> probes(n);
  for (std::size_t i = 0; i < n; ++i) {
    boxes[i] = box_of(loops[i]);
    probes[i] = probe_point(loops[i]);
  }
  for (std::size_t i = 0; i < n; ++i) {
    int parent = -1;
    double parent_area = 0.0;
    for (std::size_t j = 0; j < n; ++j) {
      if (i == j) continue;
      const double aj = std::abs(loops[j].area_mm2);
      if (aj <= std::abs(loops[i].area_mm2) || !boxes[j].contains(boxes[i])) continue;
      if (winding_number(loops[j], probes[i]) == 0) continue;
      if (parent < 0 || aj < parent_area) {
        parent = static_cast<int>(j);
        parent_area = aj;
      }
    }
    loops[i].parent = parent;
  }
  // Depth by walking up; parents always have larger area, so this terminates.
  for (std::size_t i = 0; i < n; ++i) {
    int d = 0;
    for (int p = loops[i].parent; p >= 0; p = loops[static_cast<std::size_t>(p)].parent) ++d;
    loops[i].depth = d;
  }
}

}  // namespace lamina::slice_detail
