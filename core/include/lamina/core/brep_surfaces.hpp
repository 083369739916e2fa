#pragma once
// What a B-rep (STEP, IGES) knows that a mesh does not: which CAD face each triangle lies on, what
// surface that face is, and the surface's own normal. Readers of B-rep files fill it in the
// file's frame; build_mesh carries it into the build frame, where the bevel plan reads normals
// through surface_normal_at (lamina/core/surface_normal.hpp).
#include <Eigen/Core>

#include <cstdint>
#include <string>
#include <vector>

namespace lamina {

// The face's underlying surface (OCCT's GeomAbs_SurfaceType, named as a CAD user knows them).
enum class SurfaceKind : std::uint8_t { plane, cylinder, cone, sphere, torus, bspline, bezier, revolution, extrusion, offset, other };
const char* surface_kind_name(SurfaceKind kind);

// One B-rep face. Analytic surfaces carry their geometry (mm; in the file's frame in a
// TriangleSoup, in the build frame in a Mesh), so a normal anywhere on them is exact:
//   plane:    `axis` is its normal;
//   cylinder: `origin` on the axis, `axis`, `radius_mm`;
//   cone:     `origin` on the axis where the radius is `radius_mm`, `axis` (the radius grows along
//             it), `semi_angle_rad`;
//   sphere:   `origin` the centre, `radius_mm`;
//   torus:    `origin` the centre, `axis`, `radius_mm` (major), `minor_radius_mm`.
// The rest (B-spline, Bézier, revolution, extrusion, offset) have no closed form here: their
// normals come from the corners' exact normals (BrepData::corner_normals).
struct BrepFace {
  SurfaceKind kind = SurfaceKind::other;
  std::int32_t solid = 0;  // index into BrepData::solids
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();
  double radius_mm = 0, minor_radius_mm = 0, semi_angle_rad = 0;
};

// One solid as the file names it (the product or component name; its path in the assembly).
struct BrepSolid {
  std::string name;
  std::size_t faces = 0, triangles = 0;
};

struct BrepData {
  std::vector<std::int32_t> triangle_face;      // per triangle of the soup: its face's index
  std::vector<Eigen::Vector3f> corner_normals;  // per corner: the surface's unit outward normal (zero: undefined, as at a cone's apex)
  std::vector<BrepFace> faces;
  std::vector<BrepSolid> solids;
  std::string length_unit;  // the file's own length unit, as it names it ("INCH", "MILLIMETRE"); corners are mm
  double chord_tolerance_mm = 0;  // the tessellation's: no triangle farther than this from its face
};

}  // namespace lamina
