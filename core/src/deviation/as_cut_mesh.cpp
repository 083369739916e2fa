// The parts as cut as a mesh (as_cut.hpp's as_cut_mesh): each slab's rings grouped into outer
// rings and their holes, each group a prism from the slab's bottom to its top.
#include "lamina/core/as_cut.hpp"

#include "geometry/polygon_triangulation.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace lamina {
namespace {

// Even-odd test of a point against one ring.
bool inside(const Polygon2& ring, const Eigen::Vector2d& p) {
  bool in = false;
  for (std::size_t i = 0, j = ring.size() - 1; i < ring.size(); j = i++) {
    const Eigen::Vector2d &a = ring[i], &b = ring[j];
    if ((a.y() > p.y()) != (b.y() > p.y()) && p.x() < a.x() + (p.y() - a.y()) * (b.x() - a.x()) / (b.y() - a.y())) in = !in;
  }
  return in;
}

struct Group {
  const Polygon2* outer = nullptr;
  std::vector<Polygon2> holes;
};

// Each hole (clockwise) goes to the smallest outer ring (counter-clockwise) around its first point.
std::vector<Group> groups_of(const std::vector<Polygon2>& rings) {
  std::vector<Group> groups;
  std::vector<double> areas;
  for (const Polygon2& r : rings)
    if (r.size() >= 3 && signed_area_mm2(r) > 0.0) groups.push_back({&r, {}}), areas.push_back(signed_area_mm2(r));
  for (const Polygon2& r : rings) {
    if (r.size() < 3 || signed_area_mm2(r) >= 0.0) continue;
    std::size_t best = groups.size();
    for (std::size_t g = 0; g < groups.size(); ++g)
      if (inside(*groups[g].outer, r.front()) && (best == groups.size() || areas[g] < areas[best])) best = g;
    if (best < groups.size()) groups[best].holes.push_back(r);
  }
  return groups;
}

void add_triangle(TriangleSoup& soup, const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  for (const Eigen::Vector3d* p : {&a, &b, &c}) soup.corners.push_back(p->cast<float>());
}

// A closed prism: the top cap as triangulated, the bottom cap reversed, a wall quad per edge.
void add_prism(TriangleSoup& soup, const Group& g, double z0, double z1) {
  std::vector<Eigen::Vector2d> vertices(g.outer->begin(), g.outer->end());
  for (const Polygon2& h : g.holes) vertices.insert(vertices.end(), h.begin(), h.end());
  const auto at = [&](const Eigen::Vector2d& p, double z) { return Eigen::Vector3d(p.x(), p.y(), z); };
  for (const auto& t : geometry_detail::triangulate_polygon_with_holes(*g.outer, g.holes)) {
    const auto& a = vertices[static_cast<std::size_t>(t[0])];
    const auto& b = vertices[static_cast<std::size_t>(t[1])];
    const auto& c = vertices[static_cast<std::size_t>(t[2])];
    add_triangle(soup, at(a, z1), at(b, z1), at(c, z1));
    add_triangle(soup, at(a, z0), at(c, z0), at(b, z0));
  }
  // Outer rings run counter-clockwise and holes clockwise: the material is on the left of every
  // edge, so (a, b) at the bottom, b at the top faces out.
  const auto walls = [&](const Polygon2& ring) {
    for (std::size_t i = 0; i < ring.size(); ++i) {
      const Eigen::Vector2d &a = ring[i], &b = ring[(i + 1) % ring.size()];
      add_triangle(soup, at(a, z0), at(b, z0), at(b, z1));
      add_triangle(soup, at(a, z0), at(b, z1), at(a, z1));
    }
  };
  walls(*g.outer);
  for (const Polygon2& h : g.holes) walls(h);
}

}  // namespace

TriangleSoup as_cut_mesh(std::span<const AsCutSlab> slabs) {
  TriangleSoup soup;
  soup.format = "stl-binary";
  for (const AsCutSlab& s : slabs)
    for (const Group& g : groups_of(s.rings)) add_prism(soup, g, s.z_bottom_mm, s.z_top_mm);
  return soup;
}

}  // namespace lamina
