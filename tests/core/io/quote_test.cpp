// MeshReadOptions::quote_file_text (issue 16, item 9): laminad plans files its clients name, and
// a reader's message must not become a way to read them. Every error site and note that quotes
// the file, each fed a file holding a secret: with quoting off the message keeps its position and
// what was expected but not the secret; with quoting on (a person's own file) the secret is there.
#include "io_test_util.hpp"
#include "lamina/core/mesh_io.hpp"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cstdlib>
#include <functional>
#include <string>

namespace lamina {
namespace {

using test::as_bytes;
using test::make_zip;
using test::rels;
using test::stored;

constexpr std::string_view kSecret = "Secret-Kj7Q";
constexpr std::string_view kNumber = "918273645";  // a secret that reads as a number

using Reader = std::function<std::expected<TriangleSoup, Error>(const MeshReadOptions&)>;

Reader stl(std::string bytes) {
  return [bytes](const MeshReadOptions& o) { return parse_stl(as_bytes(bytes), "in.stl", o); };
}
Reader obj(std::string text) {
  return [text](const MeshReadOptions& o) { return parse_obj(text, "in.obj", o); };
}
Reader three_mf(std::vector<std::byte> zip) {
  return [zip](const MeshReadOptions& o) { return parse_3mf(zip, "in.3mf", o); };
}
// A package of one model part (at `path`) holding `resources` and `build`.
Reader model_3mf(const std::string& resources, const std::string& build, std::string_view unit = "millimeter",
                 std::string_view path = "3D/3dmodel.model") {
  return three_mf(test::package(test::model(resources, build, unit), path));
}
const std::string& kTriangle = test::kTriangleObject;

// Through read_mesh_file, which tells the format from the content.
Reader file(std::string bytes) {
  return [bytes](const MeshReadOptions& o) {
    test::TempDir dir;
    return read_mesh_file(dir.write("in.mesh", as_bytes(bytes)), o);
  };
}

// A binary STL whose count (bytes 80-83) is `count` and which holds no triangle; not text.
std::string binary_counting(std::uint32_t count) {
  std::string b(84, '\x01');
  for (int i = 0; i < 4; ++i) b[80 + i] = static_cast<char>(count >> (8 * i));
  return b;
}

std::string ascii_facet() {
  return "facet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\n";
}

struct Case {
  std::string what;
  Reader read;
  std::string secret;
  std::string kept;    // in the message either way: where, what was expected
  std::string note = {};  // for a file that reads: the note that quotes it
  MeshReadOptions limits = {};
};

std::vector<Case> cases() {
  const std::string s(kSecret), num(kNumber);
  const std::string obj_vertices = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
  const std::string tri = R"(<object id="1"><mesh><vertices><vertex x="0" y="0" z="0"/><vertex x="1" y="0" z="0"/>)"
                          R"(<vertex x="0" y="1" z="0"/></vertices><triangles>)";
  return {
      {"STL text not starting with solid", stl(s + " and more\n"), s, "does not start with 'solid'"},
      {"binary STL with an implausible count", stl(binary_counting(918273645)), num, "not an STL file"},
      {"binary STL count beyond its size", stl(binary_counting(91827364)), "91827364", "0 complete triangles"},
      {"ASCII STL token where a keyword goes", stl("solid x\n" + s + "\n"), s, "in.stl:2: ASCII STL: expected"},
      {"ASCII STL bad normal", stl("solid x\nfacet normal " + s + " 0 0\n"), s, "in.stl:2:"},
      {"ASCII STL bad vertex", stl("solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 " + s), s, "in.stl:4:"},
      {"ASCII STL after endsolid", stl("solid x\n" + ascii_facet() + "endsolid x\n" + s), s, "in.stl:10:"},
      {"ASCII STL solid names", stl("solid " + s + "\n" + ascii_facet() + "endsolid\nsolid b\n" + ascii_facet() +
                                    "endsolid\n"),
       s, "", "multiple_solids"},
      {"OBJ coordinate", obj("v 1 " + s + " 3\n"), s, "in.obj:1: OBJ: expected a vertex coordinate"},
      {"OBJ face corner", obj(obj_vertices + "f 1 2 " + s + "\n"), s, "in.obj:4: OBJ: expected a face corner"},
      {"OBJ relative index", obj(obj_vertices + "f 1 2 -" + num + "\n"), num, "in.obj:4:"},
      {"OBJ index past 32 bits", obj(obj_vertices + "f 1 2 99" + num + "\n"), num, "in.obj:4:"},
      {"OBJ index past the vertices", obj(obj_vertices + "f 1 2 " + num + "\n"), num, "(the file defines 3 vertices)"},
      {"OBJ unknown statement", obj(s + " 1\n" + obj_vertices + "f 1 2 3\n"), s, "", "unknown_statements"},
      {"OBJ by content", file("# x\nv 0 0 0\nv " + s + " 0 0\n"), s, "in.mesh:3: OBJ"},
      {"3MF transform", model_3mf(kTriangle, "<item objectid=\"1\" transform=\"" + s + "\"/>\n"), s,
       "line 9: malformed transform"},
      {"3MF triangle index",
       model_3mf(tri + "<triangle v1=\"0\" v2=\"1\" v3=\"" + num + "\"/></triangles></mesh></object>\n", ""), num,
       "line 4: triangle vertex index"},
      {"3MF duplicate id", model_3mf("<object id=\"" + num + "\"/>\n<object id=\"" + num + "\"/>\n", ""), num,
       "line 5: duplicate object id"},
      {"3MF missing object", model_3mf(kTriangle, "<item objectid=\"" + num + "\"/>\n"), num, "line 9: object"},
      {"3MF unit", model_3mf(kTriangle, "<item objectid=\"1\"/>\n", s), s, "", "units"},
      {"3MF model part named by the relationships", three_mf(make_zip({stored("_rels/.rels", rels("/3D/" + s))})), s,
       "the zip has no model part"},
      {"zip entry with an unknown method",
       three_mf(make_zip({stored("_rels/.rels", rels("/3D/" + s)), {"3D/" + s, "x", 99, 0, 1}})), s,
       "uses compression method"},
      {"zip entry failing its CRC",
       three_mf(make_zip({stored("_rels/.rels", rels("/3D/" + s)), {"3D/" + s, "<model/>", 0, 1234, 8}})), s,
       "fails its CRC-32 check"},
      {"3MF build over the triangle bound",
       model_3mf(kTriangle + "<object id=\"" + num + "\"><components><component objectid=\"1\"/><component "
                             "objectid=\"1\"/></components></object>\n",
                 "<item objectid=\"" + num + "\"/>\n", "millimeter", "3D/" + s + ".model"),
       s + "|" + num, "the build expands to 2 triangles", "", MeshReadOptions{.max_triangles = 1}},
  };
}

bool contains(std::string_view text, std::string_view secrets) {
  for (std::size_t at = 0; at <= secrets.size();) {
    const std::size_t bar = std::min(secrets.find('|', at), secrets.size());
    if (text.find(secrets.substr(at, bar - at)) != std::string_view::npos) return true;
    at = bar + 1;
  }
  return false;
}

// The message of the error, or of the note `note` when the file reads.
std::string message_of(const std::expected<TriangleSoup, Error>& r, const Case& c) {
  if (!c.note.empty()) {
    EXPECT_TRUE(r) << c.what << ": " << r.error().message;
    if (!r) return {};
    const ReadNote* n = test::find_note(*r, c.note);
    EXPECT_NE(n, nullptr) << c.what;
    return n != nullptr ? n->message : std::string();
  }
  EXPECT_FALSE(r) << c.what << " was read";
  return r ? std::string() : r.error().message;
}

TEST(QuoteFileText, OffNoMessageHoldsTheFilesBytesOnTheyAreQuoted) {
  for (const Case& c : cases()) {
    MeshReadOptions quoting = c.limits, neutral = c.limits;
    neutral.quote_file_text = false;
    const auto quoted = c.read(quoting);
    const auto described = c.read(neutral);
    const std::string on = message_of(quoted, c), off = message_of(described, c);
    EXPECT_TRUE(contains(on, c.secret)) << c.what << ", quoting on: " << on;
    EXPECT_FALSE(contains(off, c.secret)) << c.what << ", quoting off: " << off;
    EXPECT_NE(off.find(c.kept), std::string::npos) << c.what << ": lost '" << c.kept << "': " << off;
    if (c.note.empty() && !quoted && !described) {
      EXPECT_EQ(quoted.error().code, described.error().code) << c.what;
    }
    if (std::getenv("LAMINA_SHOW_MESSAGES") != nullptr) fmt::print("{}\n  on:  {}\n  off: {}\n", c.what, on, off);
  }
}

TEST(QuoteFileText, NeutralMessagesSayHowLongTheHiddenBytesAre) {
  MeshReadOptions neutral;
  neutral.quote_file_text = false;
  auto r = parse_obj("v 1 " + std::string(kSecret) + " 3\n", "in.obj", neutral);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().message, "in.obj:1: OBJ: expected a vertex coordinate, found a token of 11 bytes");
  auto zip = parse_3mf(make_zip({stored("_rels/.rels", rels("/3D/x.model")), {"3D/x.model", "x", 99, 0, 1}}), "in.3mf",
                       neutral);
  ASSERT_FALSE(zip);
  EXPECT_NE(zip.error().message.find("zip entry number 2 (a name of 10 bytes)"), std::string::npos)
      << zip.error().message;
}

}  // namespace
}  // namespace lamina
