// tessellate: BRepMesh on each solid (edges shared by two faces are discretised once, so their
// triangles meet exactly), then every face's triangulation into the soup, wound by the face's
// orientation, with its surface's kind, analytic geometry and exact normals at the nodes.
#include "cad_tessellate.hpp"

#include <BRepAdaptor_Surface.hxx>
#include <BRepMesh_IncrementalMesh.hxx>
#include <BRep_Tool.hxx>
#include <IMeshTools_Parameters.hxx>
#include <Poly_Triangulation.hxx>
#include <TopExp_Explorer.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Face.hxx>
#include <gp_Cone.hxx>
#include <gp_Cylinder.hxx>
#include <gp_Pln.hxx>
#include <gp_Sphere.hxx>
#include <gp_Torus.hxx>

#include <fmt/format.h>

namespace lamina::step_detail {
namespace {

Eigen::Vector3d vec(const gp_XYZ& p) { return {p.X(), p.Y(), p.Z()}; }

SurfaceKind kind_of(GeomAbs_SurfaceType type) {
  switch (type) {
    case GeomAbs_Plane: return SurfaceKind::plane;
    case GeomAbs_Cylinder: return SurfaceKind::cylinder;
    case GeomAbs_Cone: return SurfaceKind::cone;
    case GeomAbs_Sphere: return SurfaceKind::sphere;
    case GeomAbs_Torus: return SurfaceKind::torus;
    case GeomAbs_BSplineSurface: return SurfaceKind::bspline;
    case GeomAbs_BezierSurface: return SurfaceKind::bezier;
    case GeomAbs_SurfaceOfRevolution: return SurfaceKind::revolution;
    case GeomAbs_SurfaceOfExtrusion: return SurfaceKind::extrusion;
    case GeomAbs_OffsetSurface: return SurfaceKind::offset;
    default: return SurfaceKind::other;
  }
}

// The face's surface as BrepFace (the adaptor applies the face's placement).
BrepFace describe(const BRepAdaptor_Surface& s, std::int32_t solid) {
  BrepFace f;
  f.kind = kind_of(s.GetType());
  f.solid = solid;
  switch (f.kind) {
    case SurfaceKind::plane:
      f.origin = vec(s.Plane().Location().XYZ()), f.axis = vec(s.Plane().Axis().Direction().XYZ());
      break;
    case SurfaceKind::cylinder:
      f.origin = vec(s.Cylinder().Location().XYZ()), f.axis = vec(s.Cylinder().Axis().Direction().XYZ());
      f.radius_mm = s.Cylinder().Radius();
      break;
    case SurfaceKind::cone:
      f.origin = vec(s.Cone().Location().XYZ()), f.axis = vec(s.Cone().Axis().Direction().XYZ());
      f.radius_mm = s.Cone().RefRadius(), f.semi_angle_rad = s.Cone().SemiAngle();
      break;
    case SurfaceKind::sphere:
      f.origin = vec(s.Sphere().Location().XYZ()), f.radius_mm = s.Sphere().Radius();
      break;
    case SurfaceKind::torus:
      f.origin = vec(s.Torus().Location().XYZ()), f.axis = vec(s.Torus().Axis().Direction().XYZ());
      f.radius_mm = s.Torus().MajorRadius(), f.minor_radius_mm = s.Torus().MinorRadius();
      break;
    default: break;
  }
  return f;
}

// The surface's unit normal at (u, v), outward for the face; zero where it is undefined.
Eigen::Vector3f normal_at(const BRepAdaptor_Surface& s, const gp_Pnt2d& uv, bool reversed) {
  gp_Pnt p;
  gp_Vec du, dv;
  s.D1(uv.X(), uv.Y(), p, du, dv);
  gp_Vec n = du.Crossed(dv);
  const double len = n.Magnitude();
  if (!(len > 1e-12)) return Eigen::Vector3f::Zero();
  n /= reversed ? -len : len;
  return Eigen::Vector3f(static_cast<float>(n.X()), static_cast<float>(n.Y()), static_cast<float>(n.Z()));
}

struct SoupBuilder {
  TriangleSoup soup;
  BrepData& brep;
  std::size_t untriangulated = 0;
  explicit SoupBuilder() : brep(soup.brep.emplace()) {}

  // One face's triangles; false when the triangle budget is spent.
  bool add_face(const TopoDS_Face& face, std::int32_t solid, std::uint64_t max_triangles) {
    const BRepAdaptor_Surface surface(face, Standard_True);
    const auto face_index = static_cast<std::int32_t>(brep.faces.size());
    brep.faces.push_back(describe(surface, solid));
    TopLoc_Location placement;
    const Handle(Poly_Triangulation) tri = BRep_Tool::Triangulation(face, placement);
    if (tri.IsNull() || tri->NbTriangles() == 0) {
      ++untriangulated;
      return true;
    }
    if (soup.triangle_count() + static_cast<std::uint64_t>(tri->NbTriangles()) > max_triangles) return false;
    const gp_Trsf to_file = placement.Transformation();
    const bool reversed = face.Orientation() == TopAbs_REVERSED;
    for (Standard_Integer t = 1; t <= tri->NbTriangles(); ++t) {
      Standard_Integer n[3];
      tri->Triangle(t).Get(n[0], n[1], n[2]);
      if (reversed) std::swap(n[1], n[2]);
      for (Standard_Integer node : n) {
        const gp_Pnt p = tri->Node(node).Transformed(to_file);
        soup.corners.emplace_back(static_cast<float>(p.X()), static_cast<float>(p.Y()), static_cast<float>(p.Z()));
        brep.corner_normals.push_back(tri->HasUVNodes() ? normal_at(surface, tri->UVNode(node), reversed)
                                                        : Eigen::Vector3f::Zero());
      }
      brep.triangle_face.push_back(face_index);
    }
    return true;
  }
};

}  // namespace

std::expected<TriangleSoup, Error> tessellate(const CadDocument& doc, const std::string& name,
                                              const CadReadOptions& options, Deadline& deadline) {
  SoupBuilder b;
  b.soup.format = doc.format;
  b.brep.length_unit = doc.length_unit;
  b.brep.chord_tolerance_mm = options.chord_tolerance_mm;
  IMeshTools_Parameters mesh;
  mesh.Deflection = options.chord_tolerance_mm;
  mesh.Angle = options.angle_tolerance_rad;
  mesh.Relative = Standard_False;
  mesh.InParallel = Standard_True;
  mesh.MeshAlgo = IMeshTools_MeshAlgoType_Delabella;
  for (std::size_t s = 0; s < doc.solids.size(); ++s) {
    const LocatedSolid& solid = doc.solids[s];
    BRepMesh_IncrementalMesh(solid.shape, mesh, deadline.Start());
    if (deadline.passed())
      return std::unexpected(Error{ErrorCode::limit_exceeded,
                                   fmt::format("{}: tessellating solid {} of {} took longer than the limit (chord "
                                               "tolerance {} mm)", name, s + 1, doc.solids.size(), mesh.Deflection)});
    BrepSolid info{options.quote_file_text ? solid.name : std::string(), 0, b.soup.triangle_count()};
    for (TopExp_Explorer face(solid.shape, TopAbs_FACE); face.More(); face.Next(), ++info.faces)
      if (!b.add_face(TopoDS::Face(face.Current()), static_cast<std::int32_t>(s), options.max_triangles))
        return std::unexpected(Error{ErrorCode::limit_exceeded,
                                     fmt::format("{}: the tessellation passes {} triangles at solid {} (chord tolerance "
                                                 "{} mm): give a coarser --chord-tolerance", name,
                                                 options.max_triangles, s + 1, mesh.Deflection)});
    info.triangles = b.soup.triangle_count() - info.triangles;
    b.brep.solids.push_back(std::move(info));
  }
  if (b.untriangulated > 0)
    b.soup.notes.push_back({"faces_not_tessellated", fmt::format("{} B-rep face(s) could not be tessellated: the mesh "
                                                                 "has holes there", b.untriangulated)});
  return std::move(b.soup);
}

}  // namespace lamina::step_detail
