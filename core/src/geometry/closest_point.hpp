#pragma once
// Private: nearest distance from points to a set of triangles, through a bounding-volume
// hierarchy (median split on the longest axis of the centroids, 4 triangles per leaf).
#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <vector>

namespace lamina::geometry_detail {

// Squared distance from p to the triangle abc (closest point by Voronoi regions, Ericson 5.1.5);
// degenerate triangles are measured as their edges.
double point_triangle_distance2(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                const Eigen::Vector3d& c);

// Reorders points along a Morton (Z-order) curve over their bounding box, so that consecutive
// points are near each other (queries in that order find a near triangle at once). Ties keep
// their order: the result does not depend on threads.
// How a step may use threads (TBB); results never depend on it.
enum class Threads : bool { one, many };
inline Threads threads_for(bool parallel) { return parallel ? Threads::many : Threads::one; }

void sort_morton(std::vector<Eigen::Vector3d>& points, Threads threads);

class TriangleTree {
 public:
  TriangleTree(const std::vector<Eigen::Vector3d>& vertices, const std::vector<std::array<std::int32_t, 3>>& faces,
               Threads threads);

  bool empty() const { return tris_.empty(); }

  // Samples of the mesh ready for queries in order, without sorting or copying them: every vertex
  // of the triangles once, then every triangle's centroid ((a + b + c) / 3 of its corners in the
  // mesh's order), both in the tree's order, which is near each other as on the surface. (As one
  // vector they were 36 MB for the 1M sphere, at the deviation's peak.)
  std::size_t surface_sample_count() const { return verts_.size() + tris_.size(); }
  Eigen::Vector3d surface_sample(std::size_t i) const {
    if (i < verts_.size()) return verts_[i];
    const auto& t = tris_[i - verts_.size()];
    return (verts_[static_cast<std::size_t>(t[0])] + verts_[static_cast<std::size_t>(t[1])] +
            verts_[static_cast<std::size_t>(t[2])]) /
           3.0;
  }

  // Distance from p to the nearest triangle. When a triangle within `enough` is found the search
  // may stop there and return that triangle's distance (≤ enough): callers after a maximum of
  // nearest distances lose nothing by it. `hint` (a triangle of an earlier, nearby query; -1 for
  // none) is tried first, with its neighbours in the tree's order, and receives the nearest
  // triangle found.
  double distance(const Eigen::Vector3d& p, double enough, std::int32_t& hint) const;

 private:
  // 32 bytes: the box in floats, rounded outwards, so it still holds its triangles (a query only
  // prunes by it; distances are measured on the triangles in doubles). 56 bytes in doubles: the
  // 1M sphere's tree was 12 MB larger, at the plan's peak.
  struct Node {
    Eigen::Vector3f lo, hi;
    std::int32_t first = 0;  // leaf: first triangle; inner: index of the right child (left is next)
    std::int32_t count = 0;  // leaf: triangles (> 0); inner: 0
  };
  std::vector<Node> nodes_;
  // The triangles in leaf order, as corners into verts_, which holds each vertex once in the
  // order the triangles first use it (near each other in memory as on the surface): 24 bytes a
  // triangle for a closed mesh instead of 72 for three copies of its corners.
  std::vector<std::array<std::int32_t, 3>> tris_;
  std::vector<Eigen::Vector3d> verts_;
  double distance2_to(std::size_t triangle, const Eigen::Vector3d& p) const {
    const auto& t = tris_[triangle];
    return point_triangle_distance2(p, verts_[static_cast<std::size_t>(t[0])], verts_[static_cast<std::size_t>(t[1])],
                                    verts_[static_cast<std::size_t>(t[2])]);
  }
};

}  // namespace lamina::geometry_detail
