// Binary STL: detection by size, exact corners, notes (trailing bytes, stored normals, NaN),
// truncated and too-short files.
#include "io_test_util.hpp"
#include "lamina/core/mesh_io.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace lamina {
namespace {

using test::binary_stl;
using test::find_note;
using test::StlFacet;

const std::vector<StlFacet> kTwoBinaryFacets = {
    {{0, 0, 1}, {1.5f, -2.25f, 3e-5f}, {100.125f, 0.0f, -7.0f}, {-0.0f, 1e20f, 42.0f}},
    {{1, 0, 0}, {4.0f, 5.0f, 6.0f}, {7.0f, 8.0f, 9.0f}, {-1.0f, -2.0f, -3.5f}},
};

void expect_corners(const TriangleSoup& soup, const std::vector<StlFacet>& facets) {
  ASSERT_EQ(soup.corners.size(), 3 * facets.size());
  for (std::size_t t = 0; t < facets.size(); ++t) {
    const std::array<float, 3>* corners[3] = {&facets[t].a, &facets[t].b, &facets[t].c};
    for (int k = 0; k < 3; ++k)
      for (int d = 0; d < 3; ++d)
        EXPECT_EQ(soup.corners[3 * t + k][d], (*corners[k])[d]) << "triangle " << t << " corner " << k;
  }
}

TEST(StlBinary, ReadsExactCornersInFileOrder) {
  const auto bytes = binary_stl(kTwoBinaryFacets);
  ASSERT_EQ(bytes.size(), 84u + 2 * 50u);
  auto soup = parse_stl(bytes, "two.stl");
  ASSERT_TRUE(soup) << soup.error().message;
  EXPECT_EQ(soup->format, "stl-binary");
  EXPECT_EQ(soup->triangle_count(), 2u);
  expect_corners(*soup, kTwoBinaryFacets);
  EXPECT_TRUE(soup->notes.empty()) << soup->notes.front().code;
}

TEST(StlBinary, LittleEndianBytesDecodeToKnownFloats) {
  // One facet written byte by byte: 1.0f = 00 00 80 3f, -2.0f = 00 00 00 c0, 0.5f = 00 00 00 3f.
  std::vector<std::byte> bytes(80, std::byte{0});
  for (unsigned char c : {1, 0, 0, 0}) bytes.push_back(std::byte{c});
  const unsigned char one[] = {0x00, 0x00, 0x80, 0x3f}, minus_two[] = {0x00, 0x00, 0x00, 0xc0},
                      half[] = {0x00, 0x00, 0x00, 0x3f}, zero[] = {0, 0, 0, 0};
  const unsigned char* floats[12] = {zero, zero, one, one, minus_two, half, half, one, zero, minus_two, zero, one};
  for (const unsigned char* f : floats)
    for (int i = 0; i < 4; ++i) bytes.push_back(std::byte{f[i]});
  bytes.push_back(std::byte{0});
  bytes.push_back(std::byte{0});
  auto soup = parse_stl(bytes, "bytes.stl");
  ASSERT_TRUE(soup) << soup.error().message;
  ASSERT_EQ(soup->triangle_count(), 1u);
  EXPECT_EQ(soup->corners[0], Eigen::Vector3f(1.0f, -2.0f, 0.5f));
  EXPECT_EQ(soup->corners[1], Eigen::Vector3f(0.5f, 1.0f, 0.0f));
  EXPECT_EQ(soup->corners[2], Eigen::Vector3f(-2.0f, 0.0f, 1.0f));
}

TEST(StlBinary, HeaderStartingWithSolidIsStillBinary) {
  for (std::string_view header : {"solid plate_holes", "solid", "SOLID name", "  solid x facet normal endsolid"}) {
    const auto bytes = binary_stl(kTwoBinaryFacets, header);
    auto soup = parse_stl(bytes, "solid_header.stl");
    ASSERT_TRUE(soup) << header << ": " << soup.error().message;
    EXPECT_EQ(soup->format, "stl-binary") << header;
    expect_corners(*soup, kTwoBinaryFacets);
  }
}

TEST(StlBinary, TrailingBytesAreNotedWithTheirCount) {
  {
    auto soup = parse_stl(binary_stl(kTwoBinaryFacets, "solid test.stl", 1), "one_extra.stl");
    ASSERT_TRUE(soup) << soup.error().message;
    EXPECT_EQ(soup->format, "stl-binary");
    expect_corners(*soup, kTwoBinaryFacets);
    const ReadNote* note = find_note(*soup, "trailing_bytes");
    ASSERT_NE(note, nullptr);
    EXPECT_NE(note->message.find("1 trailing byte "), std::string::npos) << note->message;
    EXPECT_NE(note->message.find("one_extra.stl"), std::string::npos) << note->message;
  }
  {
    auto soup = parse_stl(binary_stl(kTwoBinaryFacets, "x", 49), "many_extra.stl");
    ASSERT_TRUE(soup) << soup.error().message;
    EXPECT_EQ(soup->triangle_count(), 2u);
    const ReadNote* note = find_note(*soup, "trailing_bytes");
    ASSERT_NE(note, nullptr);
    EXPECT_NE(note->message.find("49 trailing bytes"), std::string::npos) << note->message;
  }
}

TEST(StlBinary, ShorterThanDeclaredIsTruncatedWithCounts) {
  // Declares 5 triangles, holds 2 complete ones and 30 bytes of a third.
  auto bytes = binary_stl(kTwoBinaryFacets, "cut", 30, 5);
  ASSERT_EQ(bytes.size(), 84u + 100u + 30u);
  auto soup = parse_stl(bytes, "cut.stl");
  ASSERT_FALSE(soup);
  EXPECT_EQ(soup.error().code, ErrorCode::truncated_file);
  const std::string& m = soup.error().message;
  EXPECT_NE(m.find("cut.stl"), std::string::npos) << m;
  EXPECT_NE(m.find("declares 5 triangles"), std::string::npos) << m;
  EXPECT_NE(m.find("2 complete triangles"), std::string::npos) << m;

  // Same with a "solid" header: the size, not the first word, decides.
  auto solid = parse_stl(binary_stl(kTwoBinaryFacets, "solid cut", 0, 3), "solid_cut.stl");
  ASSERT_FALSE(solid);
  EXPECT_EQ(solid.error().code, ErrorCode::truncated_file) << solid.error().message;
  EXPECT_NE(solid.error().message.find("declares 3 triangles"), std::string::npos) << solid.error().message;
}

TEST(StlBinary, TooShortOrEmptyIsAnError) {
  auto empty = parse_stl({}, "empty.stl");
  ASSERT_FALSE(empty);
  EXPECT_EQ(empty.error().code, ErrorCode::empty_mesh);

  const auto full = binary_stl(kTwoBinaryFacets, "");
  for (std::size_t n : {1u, 10u, 80u, 83u}) {
    auto r = parse_stl(std::span(full).first(n), "short.stl");
    ASSERT_FALSE(r) << n;
    EXPECT_EQ(r.error().code, ErrorCode::unknown_format) << n << ": " << r.error().message;
    EXPECT_NE(r.error().message.find("short.stl"), std::string::npos);
  }
}

TEST(StlBinary, ZeroDeclaredTrianglesIsEmpty) {
  auto r = parse_stl(binary_stl({}, "nothing"), "zero.stl");
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::empty_mesh) << r.error().message;
}

TEST(StlBinary, AllZeroStoredNormalsAreNoted) {
  std::vector<StlFacet> facets = kTwoBinaryFacets;
  for (auto& f : facets) f.normal = {0, 0, 0};
  auto soup = parse_stl(binary_stl(facets), "zero_normals.stl");
  ASSERT_TRUE(soup) << soup.error().message;
  expect_corners(*soup, facets);
  ASSERT_NE(find_note(*soup, "stored_normals_zero"), nullptr);
  EXPECT_EQ(find_note(*soup, "stored_normals_not_unit"), nullptr);
}

TEST(StlBinary, NonUnitStoredNormalsAreNoted) {
  std::vector<StlFacet> facets = kTwoBinaryFacets;
  facets[1].normal = {0.0f, 1.35f, 0.0f};
  auto soup = parse_stl(binary_stl(facets), "long_normal.stl");
  ASSERT_TRUE(soup) << soup.error().message;
  const ReadNote* note = find_note(*soup, "stored_normals_not_unit");
  ASSERT_NE(note, nullptr);
  EXPECT_NE(note->message.find("1 of 2"), std::string::npos) << note->message;
  EXPECT_NE(note->message.find("1.35"), std::string::npos) << note->message;
  EXPECT_EQ(find_note(*soup, "stored_normals_zero"), nullptr);

  // Slightly off unit length (float export noise) is not worth a note.
  facets[1].normal = {0.6f, 0.8f + 1e-5f, 0.0f};
  auto quiet = parse_stl(binary_stl(facets), "noise.stl");
  ASSERT_TRUE(quiet);
  EXPECT_TRUE(quiet->notes.empty());
}

TEST(StlBinary, NanAndInfCoordinatesAreKeptAndNoted) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  std::vector<StlFacet> facets = kTwoBinaryFacets;
  facets[0].b = {nan, 1.0f, 2.0f};
  facets[1].c = {3.0f, -inf, nan};
  auto soup = parse_stl(binary_stl(facets), "nan.stl");
  ASSERT_TRUE(soup) << soup.error().message;
  ASSERT_EQ(soup->triangle_count(), 2u);
  EXPECT_TRUE(std::isnan(soup->corners[1].x()));
  EXPECT_EQ(soup->corners[1].y(), 1.0f);
  EXPECT_EQ(soup->corners[5].y(), -inf);
  EXPECT_TRUE(std::isnan(soup->corners[5].z()));
  EXPECT_EQ(soup->corners[0], Eigen::Vector3f(1.5f, -2.25f, 3e-5f));
  const ReadNote* note = find_note(*soup, "non_finite_coordinates");
  ASSERT_NE(note, nullptr);
  EXPECT_NE(note->message.find("3 corner coordinates in 2 triangles"), std::string::npos) << note->message;
}

}  // namespace
}  // namespace lamina
