// ASCII STL: exact corners, number forms, whitespace/CRLF/case tolerance, several solids,
// parse errors with line numbers.
#include "io_test_util.hpp"
#include "lamina/core/mesh_io.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

namespace lamina {
namespace {

using test::as_bytes;
using test::find_note;

std::expected<TriangleSoup, Error> parse_text(std::string_view text, std::string_view name = "t.stl") {
  return parse_stl(as_bytes(text), name);
}

constexpr std::string_view kTwoFacets =
    "solid part\n"
    "  facet normal 0 0 1\n"
    "    outer loop\n"
    "      vertex 1.5 -2.25 3e-5\n"
    "      vertex 100.125 0 -7\n"
    "      vertex -0 1E+20 +42\n"
    "    endloop\n"
    "  endfacet\n"
    "  facet normal 1.0e+00 0.0e+00 0.0e+00\n"
    "    outer loop\n"
    "      vertex .5 -.25 1.000000e-03\n"
    "      vertex 7 8 9\n"
    "      vertex -1 -2 -3.5\n"
    "    endloop\n"
    "  endfacet\n"
    "endsolid part\n";

TEST(StlAscii, ReadsExactCornersAndNumberForms) {
  auto soup = parse_text(kTwoFacets);
  ASSERT_TRUE(soup) << soup.error().message;
  EXPECT_EQ(soup->format, "stl-ascii");
  ASSERT_EQ(soup->triangle_count(), 2u);
  EXPECT_EQ(soup->corners[0], Eigen::Vector3f(1.5f, -2.25f, 3e-5f));
  EXPECT_EQ(soup->corners[1], Eigen::Vector3f(100.125f, 0.0f, -7.0f));
  EXPECT_EQ(soup->corners[2], Eigen::Vector3f(-0.0f, 1e20f, 42.0f));
  EXPECT_EQ(soup->corners[3], Eigen::Vector3f(0.5f, -0.25f, 1e-3f));
  EXPECT_EQ(soup->corners[4], Eigen::Vector3f(7.0f, 8.0f, 9.0f));
  EXPECT_EQ(soup->corners[5], Eigen::Vector3f(-1.0f, -2.0f, -3.5f));
  EXPECT_TRUE(soup->notes.empty()) << soup->notes.front().code;
}

TEST(StlAscii, ToleratesCrlfTabsCaseAndMissingFinalNewline) {
  const std::string text =
      "\xEF\xBB\xBF  SOLID Mixed Case Name \r\n"
      "\tFacet Normal 0 0 1\r\n"
      "OUTER   LOOP\r\n"
      "VERTEX\t0 0 0\r\n"
      "  vertex 1 0 0 vertex 0 1 0\r\n\r\n"
      "EndLoop EndFacet\r\n"
      "ENDSOLID Mixed Case Name";
  auto soup = parse_text(text);
  ASSERT_TRUE(soup) << soup.error().message;
  EXPECT_EQ(soup->format, "stl-ascii");
  ASSERT_EQ(soup->triangle_count(), 1u);
  EXPECT_EQ(soup->corners[1], Eigen::Vector3f(1, 0, 0));
  EXPECT_EQ(soup->corners[2], Eigen::Vector3f(0, 1, 0));
}

TEST(StlAscii, WholeFileOnOneLine) {
  auto soup = parse_text(
      "solid one line facet normal 0 0 1 outer loop vertex 0 0 0 vertex 2 0 0 vertex 0 3 0 endloop endfacet "
      "facet normal 0 0 1 outer loop vertex 1 1 1 vertex 2 1 1 vertex 1 2 1 endloop endfacet endsolid one line");
  ASSERT_TRUE(soup) << soup.error().message;
  ASSERT_EQ(soup->triangle_count(), 2u);
  EXPECT_EQ(soup->corners[2], Eigen::Vector3f(0, 3, 0));
  EXPECT_EQ(soup->corners[5], Eigen::Vector3f(1, 2, 1));
  EXPECT_TRUE(soup->notes.empty());

  // The name stops at "facet" / "endsolid" only as whole words.
  auto named = parse_text("solid facets and endsolids\nfacet normal 0 0 1 outer loop vertex 0 0 0 vertex 1 0 0 "
                          "vertex 0 1 0 endloop endfacet endsolid\nsolid b endsolid\n");
  ASSERT_TRUE(named) << named.error().message;
  EXPECT_EQ(named->triangle_count(), 1u);
  const ReadNote* note = find_note(*named, "multiple_solids");
  ASSERT_NE(note, nullptr);
  EXPECT_NE(note->message.find("'facets and endsolids' 1 facets, 'b' 0 facets"), std::string::npos) << note->message;
}

TEST(StlAscii, SeveralSolidBlocksAreConcatenatedAndNoted) {
  std::string text(kTwoFacets);
  text += "solid second\nfacet normal 0 0 -1 outer loop vertex 0 0 9 vertex 0 1 9 vertex 1 0 9 endloop endfacet\n"
          "endsolid second\n\n";
  auto soup = parse_text(text);
  ASSERT_TRUE(soup) << soup.error().message;
  ASSERT_EQ(soup->triangle_count(), 3u);
  EXPECT_EQ(soup->corners[8], Eigen::Vector3f(1, 0, 9));
  const ReadNote* note = find_note(*soup, "multiple_solids");
  ASSERT_NE(note, nullptr);
  EXPECT_NE(note->message.find("2 solid blocks"), std::string::npos) << note->message;
  EXPECT_NE(note->message.find("'part' 2 facets"), std::string::npos) << note->message;
  EXPECT_NE(note->message.find("'second' 1 facets"), std::string::npos) << note->message;
}

TEST(StlAscii, MissingEndsolidIsToleratedAndNoted) {
  std::string text(kTwoFacets.substr(0, kTwoFacets.find("endsolid")));
  auto soup = parse_text(text);
  ASSERT_TRUE(soup) << soup.error().message;
  EXPECT_EQ(soup->triangle_count(), 2u);
  EXPECT_NE(find_note(*soup, "missing_endsolid"), nullptr);
}

// The error names the file, the line, what was expected and what was found.
void expect_parse_error(std::string_view text, std::size_t line, std::string_view expected, std::string_view found) {
  auto r = parse_text(text, "bad.stl");
  ASSERT_FALSE(r) << "parsed " << r->triangle_count() << " triangles";
  EXPECT_EQ(r.error().code, ErrorCode::parse_error);
  const std::string& m = r.error().message;
  EXPECT_NE(m.find("bad.stl:" + std::to_string(line) + ":"), std::string::npos) << m;
  EXPECT_NE(m.find(expected), std::string::npos) << m;
  EXPECT_NE(m.find(found), std::string::npos) << m;
}

TEST(StlAscii, MalformedTokensReportLineAndExpectation) {
  std::string misspelt(kTwoFacets);
  misspelt.replace(misspelt.find("vertex 7 8 9"), 6, "vertx ");
  expect_parse_error(misspelt, 12, "expected 'vertex'", "'vertx'");

  std::string bad_number(kTwoFacets);
  bad_number.replace(bad_number.find("100.125"), 7, "1.0.0.1");
  expect_parse_error(bad_number, 5, "expected a vertex coordinate", "'1.0.0.1'");

  std::string letters(kTwoFacets);
  letters.replace(letters.find("normal 0 0 1"), 12, "normal 0 x 1");
  expect_parse_error(letters, 2, "expected a normal component", "'x'");

  std::string missing_loop(kTwoFacets);
  missing_loop.replace(missing_loop.find("endloop"), 7, "       ");
  expect_parse_error(missing_loop, 8, "expected 'endloop'", "'endfacet'");

  std::string four_vertices(kTwoFacets);
  four_vertices.insert(four_vertices.find("    endloop"), "      vertex 1 1 1\n");
  expect_parse_error(four_vertices, 7, "expected 'endloop'", "'vertex'");

  std::string after_end(kTwoFacets);
  after_end += "garbage after the end\n";
  expect_parse_error(after_end, 17, "'solid' or end of file", "'garbage'");
}

TEST(StlAscii, EndOfFileInsideAFacetIsAParseError) {
  const std::string_view cut = kTwoFacets.substr(0, kTwoFacets.find("vertex 7 8 9") + 9);
  auto r = parse_text(cut, "cut.stl");
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::parse_error);
  EXPECT_NE(r.error().message.find("cut.stl:12: ASCII STL: unexpected end of file"), std::string::npos)
      << r.error().message;
}

TEST(StlAscii, SolidWithoutFacetsIsEmpty) {
  auto r = parse_text("solid nothing\nendsolid nothing\n");
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::empty_mesh);
}

TEST(StlAscii, TextThatIsNotStlIsUnknownFormat) {
  for (std::string_view text : {"hello world\n", "solidarity forever, this is not an STL file at all .......... "
                                                 "long enough to have an 84-byte preamble .............",
                                "<?xml version=\"1.0\"?><model/>"}) {
    auto r = parse_text(text);
    ASSERT_FALSE(r) << text;
    EXPECT_EQ(r.error().code, ErrorCode::unknown_format) << text << ": " << r.error().message;
  }
}

TEST(StlAscii, StoredNormalNotesAndNonFiniteValues) {
  const std::string text =
      "solid n\n"
      "facet normal 0 0 0 outer loop vertex nan 0 0 vertex 1 inf 0 vertex 0 1 -1e999 endloop endfacet\n"
      "facet normal 0 0 0 outer loop vertex 0 0 0 vertex 1 0 0 vertex 1e-60 1 0 endloop endfacet\n"
      "endsolid n\n";
  auto soup = parse_text(text);
  ASSERT_TRUE(soup) << soup.error().message;
  ASSERT_EQ(soup->triangle_count(), 2u);
  EXPECT_TRUE(std::isnan(soup->corners[0].x()));
  EXPECT_TRUE(std::isinf(soup->corners[1].y()));
  EXPECT_EQ(soup->corners[2].z(), -std::numeric_limits<float>::infinity());
  EXPECT_EQ(soup->corners[5].x(), 0.0f);  // below float range: rounds to zero
  EXPECT_NE(find_note(*soup, "stored_normals_zero"), nullptr);
  const ReadNote* note = find_note(*soup, "non_finite_coordinates");
  ASSERT_NE(note, nullptr);
  EXPECT_NE(note->message.find("3 corner coordinates in 1 triangles"), std::string::npos) << note->message;
}

}  // namespace
}  // namespace lamina
