// The shared real-world meshes (../shared/models, see its README): triangle counts, detected
// format, notes, and the README's signed volumes (which catch any misplaced corner).
#include "io_test_util.hpp"
#include "lamina/core/mesh_io.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <set>
#include <string>

namespace lamina {
namespace {

using test::find_note;
using test::signed_volume;

const std::filesystem::path kModels = LAMINA_SHARED_MODELS;

#define SKIP_WITHOUT_MODELS()                                                                      \
  if (!std::filesystem::is_directory(kModels))                                                      \
  GTEST_SKIP() << "shared test models not found at " << kModels.string()                           \
               << " (set -DLAMINA_SHARED_MODELS=<folder> to run these tests)"

struct ModelCase {
  const char* file;
  std::size_t triangles;
  const char* format;
  double volume;      // README, signed, as stored
  double volume_tol;  // half a unit of the README's last digit, or so
  std::set<std::string> notes;  // exactly these note codes
};

void PrintTo(const ModelCase& c, std::ostream* os) { *os << c.file; }

class SharedModel : public ::testing::TestWithParam<ModelCase> {};

TEST_P(SharedModel, CountFormatNotesAndVolumeMatchTheReadme) {
  SKIP_WITHOUT_MODELS();
  const ModelCase& c = GetParam();
  auto soup = read_mesh_file(kModels / c.file);
  ASSERT_TRUE(soup) << soup.error().message;
  EXPECT_EQ(soup->triangle_count(), c.triangles);
  EXPECT_EQ(soup->corners.size(), 3 * c.triangles);
  EXPECT_EQ(soup->format, c.format);
  std::set<std::string> codes;
  for (const ReadNote& n : soup->notes) codes.insert(n.code);
  EXPECT_EQ(codes, c.notes);
  EXPECT_NEAR(signed_volume(*soup), c.volume, c.volume_tol);
}

const ModelCase kCases[] = {
    {"spot.stl", 5856, "stl-binary", 0.7183, 1e-4, {}},
    {"featuretype.STL", 3476, "stl-binary", 11.6277, 1e-4, {}},
    {"plate_holes.STL", 1252, "stl-binary", 767362.1, 0.1, {}},
    {"quadknot.stl", 2880, "stl-binary", 1057307.8, 0.1, {}},
    {"torus.STL", 8700, "stl-binary", 4.9175, 1e-4, {}},
    {"fixed_top.stl", 4772, "stl-binary", 26449.3, 0.1, {}},
    {"openscad_example001.stl", 7816, "stl-binary", 18682.2, 0.1, {}},
    {"openscad_example006.stl", 29540, "stl-binary", 930884.2, 0.1, {}},
    {"openscad_example024.stl", 12012, "stl-binary", 203221.09, 0.01, {}},
    {"busted.STL", 3878, "stl-binary", 526.45, 0.01, {"stored_normals_zero"}},
    {"shared.STL", 24, "stl-binary", 2.0, 1e-6, {}},
    {"teapot.stl", 894, "stl-binary", 22963, 1.0, {"stored_normals_zero"}},
    {"multibody.stl", 32, "stl-ascii", 0.005683 - 0.001985, 2e-6, {"multiple_solids"}},
    {"HalfDonut_binary.stl", 288, "stl-binary", 2.3431, 1e-4, {"trailing_bytes", "stored_normals_not_unit"}},
    {"flange.stl", 21000, "stl-binary", 174336.5, 0.1, {}},
    {"dome.stl", 24960, "stl-binary", 171171.7, 0.1, {}},
    {"vase.stl", 43680, "stl-binary", 93125.9, 0.1, {}},
    // OBJ originals: spot is all triangles, quadknot all quads (fan-triangulated for the README).
    {"spot.obj", 5856, "obj", 0.7183, 1e-4, {}},
    {"quadknot.obj", 2880, "obj", 1057307.8, 0.1, {"polygons_triangulated"}},
};

INSTANTIATE_TEST_SUITE_P(Readme, SharedModel, ::testing::ValuesIn(kCases),
                         [](const ::testing::TestParamInfo<ModelCase>& info) {
                           std::string name = info.param.file;
                           std::replace_if(name.begin(), name.end(), [](char ch) { return !std::isalnum(ch); }, '_');
                           return name;
                         });

TEST(SharedModels, BinaryFilesWithSolidHeadersReallyStartWithSolid) {
  SKIP_WITHOUT_MODELS();
  // Guards the premise of the detection tests above: these three are binary despite their header.
  for (const char* file : {"plate_holes.STL", "torus.STL", "HalfDonut_binary.stl"}) {
    std::ifstream f(kModels / file, std::ios::binary);
    std::string head(5, '\0');
    f.read(head.data(), 5);
    EXPECT_EQ(head, "solid") << file;
  }
}

TEST(SharedModels, MultibodyNamesBothSolidsWithTheirFacetCounts) {
  SKIP_WITHOUT_MODELS();
  auto soup = read_mesh_file(kModels / "multibody.stl");
  ASSERT_TRUE(soup) << soup.error().message;
  const ReadNote* note = find_note(*soup, "multiple_solids");
  ASSERT_NE(note, nullptr);
  EXPECT_NE(note->message.find("2 solid blocks: 'bodyB' 12 facets, 'bodyA' 20 facets"), std::string::npos)
      << note->message;
}

TEST(SharedModels, HalfDonutNotesOneTrailingByteAndItsNormalLengths) {
  SKIP_WITHOUT_MODELS();
  auto soup = read_mesh_file(kModels / "HalfDonut_binary.stl");
  ASSERT_TRUE(soup) << soup.error().message;
  const ReadNote* trailing = find_note(*soup, "trailing_bytes");
  ASSERT_NE(trailing, nullptr);
  EXPECT_NE(trailing->message.find("1 trailing byte after the 288 declared triangles"), std::string::npos)
      << trailing->message;
  const ReadNote* normals = find_note(*soup, "stored_normals_not_unit");
  ASSERT_NE(normals, nullptr);
  EXPECT_NE(normals->message.find("lengths 0.038 to 1.35"), std::string::npos) << normals->message;  // README: 0.04–1.35
}

TEST(SharedModels, ObjAndStlOfTheSameModelAgree) {
  SKIP_WITHOUT_MODELS();
  // spot.stl was written from spot.obj triangle by triangle: same corners up to float rounding.
  auto obj = read_mesh_file(kModels / "spot.obj");
  auto stl = read_mesh_file(kModels / "spot.stl");
  ASSERT_TRUE(obj && stl);
  ASSERT_EQ(obj->corners.size(), stl->corners.size());
  float worst = 0.0f;
  for (std::size_t i = 0; i < obj->corners.size(); ++i)
    worst = std::max(worst, (obj->corners[i] - stl->corners[i]).cwiseAbs().maxCoeff());
  EXPECT_LE(worst, 1e-6f);

  // quadknot: quads in the OBJ, fan-triangulated in the STL; convex quads give the same fan.
  auto qobj = read_mesh_file(kModels / "quadknot.obj");
  auto qstl = read_mesh_file(kModels / "quadknot.stl");
  ASSERT_TRUE(qobj && qstl);
  EXPECT_EQ(qobj->triangle_count(), qstl->triangle_count());
  EXPECT_NEAR(signed_volume(*qobj), signed_volume(*qstl), 1e-6 * std::abs(signed_volume(*qstl)));
}

TEST(SharedModels, PlyIsRecognisedAsAnotherFormat) {
  SKIP_WITHOUT_MODELS();
  auto r = read_mesh_file(kModels / "fixed_top.ply");
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::unknown_format);
  EXPECT_NE(r.error().message.find("PLY"), std::string::npos) << r.error().message;
}

}  // namespace
}  // namespace lamina
