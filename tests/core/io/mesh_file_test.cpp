// read_mesh_file: open errors, dispatch by extension and by content.
#include "io_test_util.hpp"
#include "lamina/core/mesh_io.hpp"

#include <gtest/gtest.h>

#include <cerrno>
#include <cstring>
#include <string>

namespace lamina {
namespace {

using test::binary_stl;
using test::StlFacet;
using test::TempDir;

const std::vector<StlFacet> kFacet = {{{0, 0, 1}, {0, 0, 0}, {1, 0, 0}, {0, 1, 0}}};
constexpr std::string_view kAsciiStl =
    "solid s\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\n"
    "endsolid s\n";
constexpr std::string_view kObj = "# an OBJ\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n";

TEST(MeshFile, MissingFileIsIoErrorWithPathAndReason) {
  TempDir dir;
  const auto path = dir.path() / "does_not_exist.stl";
  auto r = read_mesh_file(path);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::io_error);
  EXPECT_NE(r.error().message.find(path.string()), std::string::npos) << r.error().message;
  EXPECT_NE(r.error().message.find(std::strerror(ENOENT)), std::string::npos) << r.error().message;
}

TEST(MeshFile, DirectoryIsIoError) {
  TempDir dir;
  auto r = read_mesh_file(dir.path());
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::io_error);
  EXPECT_NE(r.error().message.find(std::strerror(EISDIR)), std::string::npos) << r.error().message;
}

TEST(MeshFile, StlIsDetectedFromContentWhateverTheExtension) {
  TempDir dir;
  const auto bin = binary_stl(kFacet, "solid but binary");
  for (const char* name : {"a.stl", "b.STL", "c.dat", "noext"}) {
    auto r = read_mesh_file(dir.write(name, bin));
    ASSERT_TRUE(r) << name << ": " << r.error().message;
    EXPECT_EQ(r->format, "stl-binary") << name;
    EXPECT_EQ(r->triangle_count(), 1u);
    EXPECT_EQ(r->corners[1], Eigen::Vector3f(1, 0, 0));
  }
  auto ascii = read_mesh_file(dir.write("ascii.stl", kAsciiStl));
  ASSERT_TRUE(ascii) << ascii.error().message;
  EXPECT_EQ(ascii->format, "stl-ascii");
  EXPECT_EQ(ascii->corners[2], Eigen::Vector3f(0, 1, 0));
}

TEST(MeshFile, LargeBinaryStlReadInChunksMatchesParsingInMemory) {
  // 45 000 facets = 2.25 MB: several 1 MiB chunks, with records straddling chunk boundaries.
  std::vector<StlFacet> facets;
  for (int i = 0; i < 45000; ++i) {
    const float f = static_cast<float>(i);
    facets.push_back({{0, 0, i % 3 == 0 ? 0.0f : 1.0f}, {f, -f, 0.5f * f}, {f + 0.25f, 1e-3f * f, -f}, {-f, f, f * f}});
  }
  const auto bytes = binary_stl(facets, "solid big binary", 3);
  TempDir dir;
  auto from_file = read_mesh_file(dir.write("big.stl", bytes));
  auto in_memory = parse_stl(bytes, (dir.path() / "big.stl").string());
  ASSERT_TRUE(from_file) << from_file.error().message;
  ASSERT_TRUE(in_memory) << in_memory.error().message;
  EXPECT_EQ(from_file->format, "stl-binary");
  ASSERT_EQ(from_file->triangle_count(), 45000u);
  EXPECT_TRUE(from_file->corners == in_memory->corners);
  EXPECT_EQ(from_file->corners[3 * 44999 + 2], Eigen::Vector3f(-44999.0f, 44999.0f, 44999.0f * 44999.0f));
  ASSERT_EQ(from_file->notes.size(), in_memory->notes.size());
  for (std::size_t i = 0; i < from_file->notes.size(); ++i) {
    EXPECT_EQ(from_file->notes[i].code, in_memory->notes[i].code);
    EXPECT_EQ(from_file->notes[i].message, in_memory->notes[i].message);
  }
  EXPECT_NE(test::find_note(*from_file, "trailing_bytes"), nullptr);
  EXPECT_NE(test::find_note(*from_file, "stored_normals_not_unit"), nullptr);  // a third are zero
}

TEST(MeshFile, ObjGoesByExtensionOrRecognisableContent) {
  TempDir dir;
  for (const char* name : {"q.obj", "Q.OBJ", "q.txt"}) {
    auto r = read_mesh_file(dir.write(name, kObj));
    ASSERT_TRUE(r) << name << ": " << r.error().message;
    EXPECT_EQ(r->format, "obj") << name;
    EXPECT_EQ(r->triangle_count(), 2u) << name;
  }
  // An .obj name decides even for STL content: the OBJ parser reports it.
  auto wrong = read_mesh_file(dir.write("stl_inside.obj", kAsciiStl));
  ASSERT_FALSE(wrong);
  EXPECT_EQ(wrong.error().code, ErrorCode::empty_mesh) << wrong.error().message;
}

TEST(MeshFile, ThreeMfExtensionGoesToThe3mfReader) {
  TempDir dir;
  // Not a zip at all: the 3MF reader says so (with or without zlib compiled in).
  auto r = read_mesh_file(dir.write("part.3mf", std::string_view("PK\x03\x04 not really a zip")));
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::unknown_format) << r.error().message;
  EXPECT_NE(r.error().message.find("not a zip archive"), std::string::npos) << r.error().message;
  EXPECT_NE(r.error().message.find("part.3mf"), std::string::npos) << r.error().message;
}

TEST(MeshFile, UnknownContentIsUnknownFormat) {
  TempDir dir;
  auto text = read_mesh_file(dir.write("notes.stl", "just some words, not a mesh\n"));
  ASSERT_FALSE(text);
  EXPECT_EQ(text.error().code, ErrorCode::unknown_format) << text.error().message;
  EXPECT_NE(text.error().message.find("notes.stl"), std::string::npos);

  std::string zip("PK\x03\x04", 4);
  zip += std::string(200, '\0');
  auto archive = read_mesh_file(dir.write("model.stl", zip));
  ASSERT_FALSE(archive);
  EXPECT_EQ(archive.error().code, ErrorCode::unknown_format) << archive.error().message;
  EXPECT_NE(archive.error().message.find("zip"), std::string::npos) << archive.error().message;

  auto empty = read_mesh_file(dir.write("empty.stl", ""));
  ASSERT_FALSE(empty);
  EXPECT_EQ(empty.error().code, ErrorCode::empty_mesh) << empty.error().message;
}

TEST(MeshFile, TruncatedBinaryNamesThePath) {
  TempDir dir;
  auto bytes = binary_stl(kFacet, "cut", 0, 2);
  const auto path = dir.write("cut.stl", bytes);
  auto r = read_mesh_file(path);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::truncated_file);
  EXPECT_NE(r.error().message.find(path.string()), std::string::npos) << r.error().message;
  EXPECT_NE(r.error().message.find("1 complete"), std::string::npos) << r.error().message;
}

}  // namespace
}  // namespace lamina
