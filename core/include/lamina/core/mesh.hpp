#pragma once
// The repaired, indexed mesh in the build frame, with its topology, surfaces and diagnosis.
#include "lamina/core/error.hpp"
#include "lamina/core/triangle_soup.hpp"

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <expected>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace lamina {

enum class BuildAxis { x, y, z };

struct MeshParams {
  // The model's build direction becomes +Z (a proper rotation, so winding is kept).
  BuildAxis axis = BuildAxis::z;
  // Any build direction (need not be unit); when set it replaces `axis`. The rotation used is the
  // smallest one taking it to +Z.
  std::optional<Eigen::Vector3d> direction;
  // File units to millimetres: 1 for mm files, 25.4 for inch files.
  double scale_to_mm = 1.0;
  // Vertices closer than this fraction of the bounding-box diagonal are one vertex.
  // Real CAD exports differ by ~1e-16 on shared vertices; 1e-7 is far below any feature.
  double weld_tolerance_rel = 1e-7;
  // Facets whose area is below (weld tolerance)^2 · this factor are degenerate.
  double degenerate_area_factor = 1.0;
  // Edges whose dihedral angle (between facet normals) is above this bound surfaces. A B-rep
  // file's triangles carry their CAD faces instead: those are the surfaces, whatever the angle.
  double sharp_angle_rad = 30.0 * 3.14159265358979323846 / 180.0;
};

enum class Severity {
  info,      // worth knowing, nothing changed (several shells)
  repaired,  // found and fixed (winding, inside-out, welded cracks, degenerate facets dropped)
  warning,   // usable but results may be approximate (non-manifold edges, padded file)
  error,     // not usable as a solid (open edges, no facets, NaN-only)
};
const char* severity_name(Severity s);

struct Defect {
  std::string code;  // stable: "nan_coordinates", "degenerate_facets", "open_edges", ...
  Severity severity = Severity::info;
  std::size_t count = 0;
  std::string message;                    // one line: what, how many, an example location
  std::optional<Eigen::Vector3d> where;   // example location in the build frame (mm)
};

// An undirected mesh edge; faces listed in edge_faces[face_begin .. face_begin + face_count).
struct Edge {
  std::int32_t v0 = 0, v1 = 0;  // v0 < v1
  std::int32_t face_begin = 0;
  std::int32_t face_count = 0;  // 2 on a manifold edge, 1 on a boundary, >2 non-manifold
};

struct MeshSummary {
  std::size_t triangles_read = 0;     // as stored in the file
  std::size_t triangles = 0;          // kept after repair
  std::size_t vertices = 0;           // after welding
  bool watertight = false;            // every edge has exactly two facets, consistently wound
  double volume_mm3 = 0.0;            // of the repaired mesh, divergence theorem
  Eigen::Vector3d bbox_min_mm = Eigen::Vector3d::Zero();
  Eigen::Vector3d bbox_max_mm = Eigen::Vector3d::Zero();
  int shells = 0;
  int surfaces = 0;
  std::size_t boundary_edges = 0;
  std::size_t nonmanifold_edges = 0;
  // How far the turned model was lowered to put its lowest point at z = 0: two tessellations of
  // one B-rep (their lowest vertices differ by up to the chord) share a frame through it.
  double lowered_mm = 0.0;
};

// One shell: a connected set of facets joined through manifold edges (exactly two facets).
struct ShellInfo {
  std::int32_t facets = 0;
  double volume_mm3 = 0.0;  // signed, after orientation: > 0 a solid, < 0 a cavity
  bool closed = false;      // every edge of the shell is balanced (no boundary, no winding conflict)
  int depth = 0;            // how many other closed shells enclose it (odd = cavity)
};

struct Mesh {
  std::vector<Eigen::Vector3d> vertices;               // mm, build frame, lowest point at z = 0
  std::vector<std::array<std::int32_t, 3>> faces;      // wound outward (CCW seen from outside)
  std::vector<Eigen::Vector3d> normals;                // unit facet normals, from the winding
  std::vector<std::int32_t> surface_id;                // per facet: region bounded by sharp edges (a B-rep: its face)
  std::vector<std::int32_t> shell_id;                  // per facet: component joined by manifold edges
  std::vector<Edge> edges;
  std::vector<std::int32_t> edge_faces;                // CSR payload of Edge::face_begin/count
  std::vector<std::array<std::int32_t, 3>> face_edges; // edge of (f[0],f[1]), (f[1],f[2]), (f[2],f[0])
  std::vector<ShellInfo> shell_info;                   // indexed by shell_id
  // From a B-rep file only (empty for meshes): the surfaces, indexed by surface_id, in the build
  // frame; and per facet its corners' exact normals, in the order of faces[f].
  std::vector<BrepFace> brep_faces;
  std::vector<std::array<Eigen::Vector3f, 3>> corner_normals;
  MeshSummary summary;
  std::vector<Defect> defects;

  // False when any defect has Severity::error.
  bool usable() const;
  // The defect with this code, or nullptr.
  const Defect* find_defect(std::string_view code) const;
};

// The rotation that takes the model's build direction to +Z (axis permutations are exact).
Eigen::Matrix3d build_frame_rotation(const MeshParams& params);

// Weld, repair, orient, find shells and surfaces. Fails only when nothing usable is left
// (no finite, non-degenerate facet); every other problem becomes a Defect.
std::expected<Mesh, Error> build_mesh(const TriangleSoup& soup, const MeshParams& params);

// `other`, built from another tessellation of the same model with the same params, moved into
// `frame`'s frame: each was lowered by its own lowest vertex (summary.lowered_mm), which differ by
// up to the chord where the lowest point is on a curved face.
Mesh in_frame_of(Mesh other, const Mesh& frame);

}  // namespace lamina
