#pragma once
// Internal steps of build_mesh, one idea per file; not part of the public API.
#include "lamina/core/mesh.hpp"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <array>
#include <cstdint>
#include <string>
#include <vector>

// Stage timing for profiling builds only (-DLAMINA_MESH_TIMING); compiled out otherwise.
#ifdef LAMINA_MESH_TIMING
#include <chrono>
#include <cstdio>
#define LAMINA_TIMER() auto lamina_tick_ = std::chrono::steady_clock::now()
#define LAMINA_TICK(name)                                                                                 \
  do {                                                                                                   \
    const auto now_ = std::chrono::steady_clock::now();                                                  \
    std::fprintf(stderr, "  %-12s %7.2f ms\n", name,                                                     \
                 std::chrono::duration<double, std::milli>(now_ - lamina_tick_).count());                \
    lamina_tick_ = now_;                                                                                 \
  } while (0)
#else
#define LAMINA_TIMER() \
  do {                 \
  } while (0)
#define LAMINA_TICK(name) \
  do {                    \
  } while (0)
#endif

namespace lamina::mesh_detail {

using Tri = std::array<std::int32_t, 3>;

// Ask for transparent huge pages on [data, data + bytes) before it is first touched (Linux;
// a no-op elsewhere). Only for big tables read at random, where TLB misses would cost as much as
// the accesses; not for arrays read in order (first touch of huge pages costs more up front).
void hint_huge_pages(void* data, std::size_t bytes);

inline std::uint64_t mix64(std::uint64_t h) {
  h ^= h >> 33;
  h *= 0xff51afd7ed558ccdULL;
  h ^= h >> 33;
  h *= 0xc4ceb9fe1a85ec53ULL;
  h ^= h >> 33;
  return h;
}

inline std::size_t pow2_at_least(std::size_t n) {
  std::size_t c = 64;
  while (c < n) c <<= 1;
  return c;
}

// mesh_weld.cpp -------------------------------------------------------------------------------

struct WeldResult {
  // The distinct points (exact weld), in the build frame (rotated, scaled, not yet translated),
  // in order of first appearance in the soup.
  std::vector<Eigen::Vector3d> points;
  // Per point: the point it was welded to by the tolerance weld (the lowest index of its cluster;
  // itself when nothing was merged).
  std::vector<std::int32_t> rep;
  // Per soup corner: index into points, -1 for corners of dropped (non-finite) facets.
  std::vector<std::int32_t> corner_point;

  std::size_t nan_facets = 0;
  std::size_t first_nan_facet = 0;

  double tolerance = 0.0;  // absolute weld tolerance (mm)

  std::size_t tolerance_merged = 0;  // points merged only by the tolerance weld
  Eigen::Vector3d first_merged = Eigen::Vector3d::Zero();
};

// Drop non-finite facets, exact and tolerance weld, build frame.
WeldResult weld_soup(const TriangleSoup& soup, const MeshParams& params);

// The build-frame rotation (a cyclic permutation, det +1) and scale applied to a file point.
Eigen::Vector3d to_build_frame(const Eigen::Vector3d& p, const Eigen::Matrix3d& rotation, double scale);

// mesh_topology.cpp ---------------------------------------------------------------------------

// What build_edges leaves beside the Mesh arrays for the later steps.
struct Adjacency {
  // Per facet side (3·f + k, side k from f[k] to f[k+1]): when the edge is manifold,
  // 2·g + same, g the facet across it and same = 1 when both facets run along the edge in the
  // same direction (as wound when the table was built); else -1.
  std::vector<std::int32_t> across;
  // Edges with face_count != 2 (boundary or non-manifold), increasing.
  std::vector<std::int32_t> odd_edges;
};

// Unique undirected edges (v0 < v1, sorted by (v0, v1)) with their facets in CSR form (facets of
// an edge in increasing order), and the three edges of each facet. Counting sort of the facet
// sides by their lower vertex, then a small sort inside each vertex's bucket (in parallel).
// Flat arrays only: no map, no per-edge allocation.
Adjacency build_edges(std::size_t vertex_count, const std::vector<Tri>& faces, std::vector<Edge>& edges,
                      std::vector<std::int32_t>& edge_faces, std::vector<Tri>& face_edges);

// Local index (0..2) of edge e in facet f.
inline int local_edge(const Mesh& m, std::int32_t f, std::int32_t e) {
  const Tri& fe = m.face_edges[static_cast<std::size_t>(f)];
  return fe[0] == e ? 0 : (fe[1] == e ? 1 : 2);
}

// +1 when facet f runs along edge e from v0 to v1, -1 when from v1 to v0.
inline int edge_direction(const Mesh& m, std::int32_t f, int k) {
  const Tri& t = m.faces[static_cast<std::size_t>(f)];
  const Edge& ed = m.edges[static_cast<std::size_t>(m.face_edges[static_cast<std::size_t>(f)][k])];
  return t[k] == ed.v0 ? 1 : -1;
}

// Reverse a facet's winding, keeping face_edges and the normal consistent. (Negating the
// normal is exact: the cross product of the swapped edges is the negated product bit for bit.)
inline void flip_face(Mesh& m, std::size_t f) {
  std::swap(m.faces[f][1], m.faces[f][2]);
  std::swap(m.face_edges[f][0], m.face_edges[f][2]);
  m.normals[f] = -m.normals[f];
}

inline Eigen::Vector3d centroid(const Mesh& m, std::size_t f) {
  const Tri& t = m.faces[f];
  return (m.vertices[static_cast<std::size_t>(t[0])] + m.vertices[static_cast<std::size_t>(t[1])] +
          m.vertices[static_cast<std::size_t>(t[2])]) /
         3.0;
}

// mesh_orient.cpp -----------------------------------------------------------------------------

struct OrientResult {
  std::size_t facets_flipped = 0;     // to make the winding consistent within shells
  std::size_t winding_conflicts = 0;  // manifold edges still wound the same way on both sides
  std::size_t shells_inverted = 0;    // whole shells turned outside-in
  Eigen::Vector3d first_conflict = Eigen::Vector3d::Zero();
  Eigen::Vector3d first_flipped = Eigen::Vector3d::Zero();
  Eigen::Vector3d first_inverted = Eigen::Vector3d::Zero();
  int surfaces = 0;
};

// Shells (components over manifold edges), consistent winding and surfaces in one walk, then
// the outward orientation from signed volume and nesting parity. Needs the raw normals; fills
// shell_id, shell_info and surface_id (walk order: renumber_surfaces makes them canonical);
// turns facets (and their normals) over in place.
OrientResult orient_shells(Mesh& m, const Adjacency& adj, double sharp_angle_rad);

// mesh_brep.cpp -------------------------------------------------------------------------------

// What build_mesh keeps of a B-rep soup's facets while it welds and orients them: each kept
// facet's triangle in the soup and its vertices as first collected.
struct BrepCarry {
  std::vector<std::int32_t> source_triangle;
  std::vector<Tri> faces_as_read;
};
// Surfaces = the B-rep's faces; corner normals and face geometry into the build frame.
void apply_brep(Mesh& m, const BrepData& brep, const BrepCarry& carry, const Eigen::Matrix3d& rotation, double scale,
                double z_shift);

// Facets grouped by shell: order[begin[s] .. begin[s + 1]) are the facets of shell s.
struct ShellFaces {
  std::vector<std::int32_t> order;
  std::vector<std::int32_t> begin;
};

struct Box3 {
  Eigen::Vector3d lo, hi;
  bool contains(const Box3& o, double slack) const {
    return (lo.array() - slack <= o.lo.array()).all() && (o.hi.array() <= hi.array() + slack).all();
  }
  bool contains(const Eigen::Vector3d& p) const { return (lo.array() <= p.array()).all() && (p.array() <= hi.array()).all(); }
};

// mesh_shells.cpp -----------------------------------------------------------------------------

// Per shell: closedness, signed volume, nesting depth among closed shells (ray parity); turns
// over whole shells whose volume sign disagrees with their depth (odd depth = cavity, < 0).
// Fills shell_info.
void outward_shells(Mesh& m, const Adjacency& adj, const ShellFaces& sf, const std::vector<char>& shell_conflict,
                    OrientResult& r);

// mesh_nesting.cpp ----------------------------------------------------------------------------

// For each shell in `closed` (closed shells of non-zero volume): how many of the others enclose
// it (box inside box, larger volume, three probe points inside by ray parity). Other entries 0.
std::vector<int> nesting_depths(const Mesh& m, const ShellFaces& sf, const std::vector<std::size_t>& closed,
                                const std::vector<Box3>& box, const std::vector<double>& vol);

// mesh_surfaces.cpp ---------------------------------------------------------------------------

// Unit facet normals from the winding (parallel).
void compute_normals(Mesh& m);

// Surface ids in order of each surface's lowest facet (what growing from seeds in facet order
// gives), whatever order the walk found them in.
void renumber_surfaces(Mesh& m, int surfaces);

// mesh_build.cpp helpers ----------------------------------------------------------------------

std::string format_point(const Eigen::Vector3d& p);

}  // namespace lamina::mesh_detail
