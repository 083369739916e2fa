// The STEP / IGES reader against parts whose answers are known: made here with OpenCASCADE and
// written as a customer's file, and the shared models with their measured properties.
#include <gtest/gtest.h>

#include "occt_shapes.hpp"

#include "lamina/core/mesh.hpp"
#include "lamina/core/surface_normal.hpp"
#include "lamina/step/cad_reader.hpp"

#include <BRepGProp.hxx>
#include <GProp_GProps.hxx>

#include <fmt/format.h>

#include <fstream>
#include <map>

namespace lamina {
namespace {

using namespace step_testing;

struct TempFolder {
  std::filesystem::path path;
  TempFolder() {
    char tmpl[] = "/tmp/lamina-step-XXXXXX";
    path = ::mkdtemp(tmpl);
  }
  ~TempFolder() { std::filesystem::remove_all(path); }
  std::filesystem::path file(const std::string& name) const { return path / name; }
};

Mesh mesh_of(const TriangleSoup& soup) {
  auto mesh = build_mesh(soup, MeshParams{});
  EXPECT_TRUE(mesh) << mesh.error().message;
  return mesh ? std::move(*mesh) : Mesh{};
}

TriangleSoup read_ok(const std::filesystem::path& path, CadReadOptions options = {}) {
  auto soup = read_cad_file(path, options);
  EXPECT_TRUE(soup) << soup.error().message;
  return soup ? std::move(*soup) : TriangleSoup{};
}

double volume_of(const TopoDS_Shape& shape) {
  GProp_GProps props;
  BRepGProp::VolumeProperties(shape, props);
  return props.Mass();
}

std::map<std::string, int> kinds(const Mesh& m) {
  std::map<std::string, int> out;
  for (const BrepFace& f : m.brep_faces) ++out[surface_kind_name(f.kind)];
  return out;
}

Eigen::Vector3d centroid(const Mesh& m, std::size_t f) {
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (auto v : m.faces[f]) c += m.vertices[static_cast<std::size_t>(v)];
  return c / 3;
}

TEST(StepReader, AFilletedBoxHasExactlyItsFaceCountOfSurfacesWhereTheDihedralRuleMergesThem) {
  TempFolder dir;
  const TopoDS_Shape part = filleted_box(40, 30, 20, 3);
  write_cad(part, dir.file("box.step"));
  const TriangleSoup soup = read_ok(dir.file("box.step"));
  const Mesh m = mesh_of(soup);
  EXPECT_EQ(m.summary.surfaces, 26) << "6 planes, 12 cylinders, 8 spheres";
  EXPECT_EQ(kinds(m), (std::map<std::string, int>{{"plane", 6}, {"cylinder", 12}, {"sphere", 8}}));
  EXPECT_TRUE(m.summary.watertight);
  EXPECT_EQ(m.find_defect("welded_vertices"), nullptr) << "shared edges meshed once: nothing to weld";
  EXPECT_NEAR(m.summary.volume_mm3, volume_of(part), 2e-3 * volume_of(part));
  // The same triangles as a mesh: the fillets are tangent to their faces, the dihedral rule
  // (30°) joins them all into one surface.
  TriangleSoup as_mesh = soup;
  as_mesh.brep.reset();
  EXPECT_LT(mesh_of(as_mesh).summary.surfaces, 26);
}

TEST(StepReader, EveryTriangleIsOnItsFaceAndItsFaceOnTheSurfaceItNames) {
  TempFolder dir;
  write_cad(tube(20, 12, 30), dir.file("tube.stp"));
  const Mesh m = mesh_of(read_ok(dir.file("tube.stp")));
  EXPECT_EQ(kinds(m), (std::map<std::string, int>{{"plane", 2}, {"cylinder", 2}}));
  for (std::size_t f = 0; f < m.faces.size(); ++f) {
    const BrepFace& face = m.brep_faces[static_cast<std::size_t>(m.surface_id[f])];
    for (auto v : m.faces[f]) {
      const Eigen::Vector3d p = m.vertices[static_cast<std::size_t>(v)];
      if (face.kind == SurfaceKind::cylinder) {
        const Eigen::Vector3d d = p - face.origin;
        EXPECT_NEAR((d - d.dot(face.axis) * face.axis).norm(), face.radius_mm, 1e-4);
      } else {
        EXPECT_NEAR((p - face.origin).dot(face.axis), 0, 1e-4);
      }
    }
  }
}

// On an analytic face the normal is the surface's, exactly, where the facet's is a chord's.
void expect_exact_normals(const Mesh& m, const std::function<Eigen::Vector3d(const Eigen::Vector3d&)>& truth) {
  double worst_exact = 0, worst_facet = 0;
  for (std::size_t f = 0; f < m.faces.size(); ++f) {
    const Eigen::Vector3d c = centroid(m, f), n = truth(c);
    worst_exact = std::max(worst_exact, (surface_normal_at(m, static_cast<std::int32_t>(f), c) - n).norm());
    worst_facet = std::max(worst_facet, (m.normals[f] - n).norm());
  }
  EXPECT_LT(worst_exact, 1e-9);
  EXPECT_GT(worst_facet, 1e-3) << "the facets are chords: their normals are not the surface's";
}

TEST(StepReader, ASpheresAndATorussNormalsAreExact) {
  TempFolder dir;
  write_cad(sphere(15), dir.file("sphere.step"));
  write_cad(torus(20, 5), dir.file("torus.step"));
  const Mesh ball = mesh_of(read_ok(dir.file("sphere.step")));
  ASSERT_EQ(kinds(ball), (std::map<std::string, int>{{"sphere", 1}}));
  const Eigen::Vector3d centre = ball.brep_faces[0].origin;
  EXPECT_NEAR(centre.z(), 15, 1e-6) << "the lowest point is at z = 0 in the build frame";
  expect_exact_normals(ball, [&](const Eigen::Vector3d& p) { return (p - centre).normalized(); });

  const Mesh ring = mesh_of(read_ok(dir.file("torus.step")));
  ASSERT_EQ(kinds(ring), (std::map<std::string, int>{{"torus", 1}}));
  const BrepFace t = ring.brep_faces[0];
  expect_exact_normals(ring, [&](const Eigen::Vector3d& p) {
    const Eigen::Vector3d d = p - t.origin;
    const Eigen::Vector3d tube_centre = t.origin + t.radius_mm * (d - d.dot(t.axis) * t.axis).normalized();
    return Eigen::Vector3d((p - tube_centre).normalized());
  });
}

TEST(StepReader, AFreeFormFacesNormalsComeFromItsCornersExactNormals) {
  TempFolder dir;
  write_cad(bspline_solid(), dir.file("loft.step"));
  const Mesh m = mesh_of(read_ok(dir.file("loft.step")));
  ASSERT_GE(kinds(m)["bspline"], 1) << fmt::format("{}", m.brep_faces.size());
  EXPECT_TRUE(m.summary.watertight);
  std::size_t on_bspline = 0, differs = 0;
  for (std::size_t f = 0; f < m.faces.size(); ++f) {
    if (m.brep_faces[static_cast<std::size_t>(m.surface_id[f])].kind != SurfaceKind::bspline) continue;
    ++on_bspline;
    const Eigen::Vector3d n = surface_normal_at(m, static_cast<std::int32_t>(f), centroid(m, f));
    EXPECT_NEAR(n.norm(), 1, 1e-9);
    EXPECT_GT(n.dot(m.normals[f]), 0.9) << "on the facet's side, close to it";
    if ((n - m.normals[f]).norm() > 1e-6) ++differs;
  }
  EXPECT_GT(on_bspline, 10u);
  EXPECT_GT(differs, on_bspline / 2) << "interpolated from the corners, not the facet's own";
}

TEST(StepReader, AnAssemblysPlacementsAndNamesAreKept) {
  TempFolder dir;
  write_assembly(box(10, 10, 10), 30, dir.file("assembly.step"));
  const TriangleSoup soup = read_ok(dir.file("assembly.step"));
  ASSERT_TRUE(soup.brep);
  ASSERT_EQ(soup.brep->solids.size(), 2u);
  EXPECT_EQ(soup.brep->solids[0].name, "bracket/bolt 1");
  EXPECT_EQ(soup.brep->solids[1].name, "bracket/bolt 2");
  const Mesh m = mesh_of(soup);
  EXPECT_EQ(m.summary.shells, 2);
  EXPECT_NEAR(m.summary.bbox_max_mm.x() - m.summary.bbox_min_mm.x(), 40, 1e-4) << "the second placed 30 mm along x";
  EXPECT_EQ(m.summary.surfaces, 12);
}

// The demo knob as a B-rep (examples/knob.step is made by this function): its volume is the
// README's independent Pappus integral of the smooth profile; read back, its faces are the
// revolved profile's nine and the six bolt holes, of the kinds the profile makes, and the
// tessellation's volume is within what a chord allows (every point within the chord of the
// surface: at most chord × area away).
TEST(StepReader, TheDemoKnobIsItsProfileRevolvedAndReadsBackToItsVolume) {
  TempFolder dir;
  const TopoDS_Shape k = knob();
  EXPECT_NEAR(volume_of(k), 103453.37, 0.05) << "examples/README.md: the ideal volume of the smooth solid";
  write_cad(k, dir.file("knob.step"));
  CadReadOptions options;
  options.chord_tolerance_mm = 0.02;
  const Mesh m = mesh_of(read_ok(dir.file("knob.step"), options));
  EXPECT_TRUE(m.summary.watertight);
  EXPECT_EQ(m.summary.surfaces, 15);
  // OCCT 7.6 keeps the concave neck (an arc whose circle stays off the axis) as a surface of
  // revolution and recognises the round as a torus.
  auto k_kinds = kinds(m);
  EXPECT_EQ(k_kinds["plane"], 3);
  EXPECT_EQ(k_kinds["cylinder"], 9);
  EXPECT_EQ(k_kinds["sphere"], 1);
  EXPECT_EQ(k_kinds["torus"] + k_kinds["revolution"], 2);
  GProp_GProps area;
  BRepGProp::SurfaceProperties(k, area);
  EXPECT_NEAR(m.summary.volume_mm3, 103453.37, options.chord_tolerance_mm * area.Mass());
  EXPECT_NEAR(m.summary.bbox_max_mm.z(), 43.4178, options.chord_tolerance_mm) << "where the dome meets the bore";
}

TEST(StepReader, IgesIsReadToo) {
  TempFolder dir;
  write_cad(tube(20, 12, 30), dir.file("tube.igs"));
  const TriangleSoup soup = read_ok(dir.file("tube.igs"));
  EXPECT_EQ(soup.format, "iges");
  const Mesh m = mesh_of(soup);
  EXPECT_TRUE(m.summary.watertight);
  EXPECT_EQ(m.summary.surfaces, 4);
}

TEST(StepReader, BadFilesGetClearErrorsNeverACrash) {
  TempFolder dir;
  write_cad(tube(20, 12, 30), dir.file("tube.step"));
  std::ifstream in(dir.file("tube.step"), std::ios::binary);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  auto write = [&](const std::string& name, const std::string& bytes) {
    std::ofstream(dir.file(name), std::ios::binary) << bytes;
    return dir.file(name);
  };
  struct Case {
    std::filesystem::path file;
    ErrorCode code;
    std::string says;
  };
  write_cad(lone_face(), dir.file("face.step"));
  const std::vector<Case> cases{
      {write("half.step", text.substr(0, text.size() / 2)), ErrorCode::truncated_file, "cut short"},
      {write("mesh.step", "solid x\nendsolid x\n"), ErrorCode::unknown_format, "not a STEP file"},
      {write("empty.step", ""), ErrorCode::unknown_format, "not a STEP file"},
      {write("garbage.step", "ISO-10303-21;\nthis is no exchange structure\nEND-ISO-10303-21;\n"), ErrorCode::parse_error, "STEP"},
      {dir.file("face.step"), ErrorCode::empty_mesh, "no solid"},
      {dir.file("missing.step"), ErrorCode::io_error, "cannot open"},
      {write("half.igs", "not iges at all\n"), ErrorCode::truncated_file, "IGES"},
  };
  for (const Case& c : cases) {
    const auto soup = read_cad_file(c.file);
    ASSERT_FALSE(soup) << c.file;
    EXPECT_EQ(soup.error().code, c.code) << c.file << ": " << soup.error().message;
    EXPECT_NE(soup.error().message.find(c.says), std::string::npos) << soup.error().message;
    EXPECT_NE(soup.error().message.find(c.file.filename().string()), std::string::npos) << "names the file";
  }
}

TEST(StepReader, ReadingIsBoundedInTimeAndTriangles) {
  TempFolder dir;
  write_cad(sphere(15), dir.file("sphere.step"));
  CadReadOptions tight;
  tight.max_triangles = 10;
  auto soup = read_cad_file(dir.file("sphere.step"), tight);
  ASSERT_FALSE(soup);
  EXPECT_EQ(soup.error().code, ErrorCode::limit_exceeded);
  EXPECT_NE(soup.error().message.find("--chord-tolerance"), std::string::npos) << soup.error().message;
  CadReadOptions hurried;
  hurried.max_seconds = 0;
  soup = read_cad_file(dir.file("sphere.step"), hurried);
  ASSERT_FALSE(soup);
  EXPECT_EQ(soup.error().code, ErrorCode::limit_exceeded) << soup.error().message;
  CadReadOptions small_files;
  small_files.max_file_bytes = 100;
  soup = read_cad_file(dir.file("sphere.step"), small_files);
  ASSERT_FALSE(soup);
  EXPECT_EQ(soup.error().code, ErrorCode::limit_exceeded);
}

// ../shared/models: face counts, solids and sizes from its README (measured from the files).
struct SharedStep {
  const char* file;
  int faces, solids;
  Eigen::Vector3d size_mm;
};

class SharedStepModels : public ::testing::TestWithParam<SharedStep> {};

TEST_P(SharedStepModels, SurfacesAreTheFacesAndTheSolidIsWatertightInMillimetres) {
  const SharedStep& s = GetParam();
  const std::filesystem::path path = std::filesystem::path(LAMINA_SHARED_MODELS) / s.file;
  if (!std::filesystem::exists(path)) GTEST_SKIP() << path << " is not here";
  CadReadOptions coarse;
  coarse.chord_tolerance_mm = 0.05;
  const Mesh m = mesh_of(read_ok(path, coarse));
  EXPECT_EQ(m.summary.surfaces, s.faces);
  EXPECT_EQ(m.summary.shells, s.solids);
  EXPECT_TRUE(m.summary.watertight);
  EXPECT_EQ(m.summary.boundary_edges, 0u);
  const Eigen::Vector3d size = m.summary.bbox_max_mm - m.summary.bbox_min_mm;
  EXPECT_TRUE(size.isApprox(s.size_mm, 2e-3)) << size.transpose() << " against " << s.size_mm.transpose();
}

INSTANTIATE_TEST_SUITE_P(
    All, SharedStepModels,
    ::testing::Values(SharedStep{"step_cube_cylinder.step", 9, 2, {25, 10, 10}},
                      SharedStep{"step_featuretype.step", 96, 1, {127, 63.5, 34.925}},
                      SharedStep{"step_base_interface_ap203.step", 30, 1, {599.4, 638.7, 4.7625}},
                      SharedStep{"step_leg_fork.step", 118, 1, {13.5, 16.78, 62.5}},
                      SharedStep{"step_m6_screw.step", 28, 1, {10.23, 10.34, 12}},
                      SharedStep{"step_pipe_bend.step", 4, 1, {1016, 508, 1016}}),
    [](const auto& info) {
      std::string n = info.param.file;
      return n.substr(5, n.find('.') - 5);
    });

}  // namespace
}  // namespace lamina
