// The work a file can ask of the readers (issue 16, item 12): 3MF builds that expand to more
// triangles than the bound, zip entries that inflate past theirs, and the copies and allocations
// of large builds, counted rather than timed (an allocation counter, not a clock).
#include "allocation_counter.hpp"
#include "io_test_util.hpp"
#include "lamina/core/mesh_io.hpp"

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <zlib.h>

#include <random>
#include <string>

namespace lamina {
namespace {

using test::AllocationScope;
using test::kContentTypes;
using test::kTriangleObject;
using test::make_zip;
using test::model;
using test::package;
using test::rels;
using test::stored;
using test::ZipItem;

// Raw deflate (no zlib header, as zip holds it) of `data`.
std::string raw_deflate(std::string_view data) {
  z_stream zs{};
  EXPECT_EQ(deflateInit2(&zs, 6, Z_DEFLATED, -MAX_WBITS, 9, Z_DEFAULT_STRATEGY), Z_OK);
  std::string out(deflateBound(&zs, static_cast<uLong>(data.size())), '\0');
  zs.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(data.data()));
  zs.avail_in = static_cast<uInt>(data.size());
  zs.next_out = reinterpret_cast<Bytef*>(out.data());
  zs.avail_out = static_cast<uInt>(out.size());
  EXPECT_EQ(deflate(&zs, Z_FINISH), Z_STREAM_END);
  out.resize(zs.total_out);
  deflateEnd(&zs);
  return out;
}

// A package whose model part is `xml` deflated, declaring `declared_size` (its true size if 0).
std::vector<std::byte> deflated_package(const std::string& xml, std::uint32_t declared_size = 0) {
  return make_zip({stored("[Content_Types].xml", kContentTypes), stored("_rels/.rels", rels("/3D/3dmodel.model")),
                   ZipItem{"3D/3dmodel.model", raw_deflate(xml), 8, test::crc32(xml),
                           declared_size != 0 ? declared_size : static_cast<std::uint32_t>(xml.size())}});
}

// Object k + 1 holds `fanout` components of object k, k = 1 … levels; one item of the top.
std::vector<std::byte> nested_components(int levels, int fanout) {
  std::string resources = kTriangleObject;
  for (int k = 1; k <= levels; ++k) {
    resources += fmt::format("<object id=\"{}\"><components>", k + 1);
    for (int c = 0; c < fanout; ++c) resources += fmt::format("<component objectid=\"{}\"/>", k);
    resources += "</components></object>\n";
  }
  return package(model(resources, fmt::format("<item objectid=\"{}\"/>\n", levels + 1)));
}

TEST(ReadLimits, NestedComponentsBeyondTheTriangleBoundAreRefusedBeforeAnyIsMade) {
  // 12 levels of 10 components: 10^12 triangles from a package of 5 kB.
  const auto zip = nested_components(12, 10);
  ASSERT_LT(zip.size(), 6000u);
  AllocationScope counted;
  auto r = parse_3mf(zip, "bomb.3mf");
  ASSERT_FALSE(r) << r->triangle_count();
  EXPECT_EQ(r.error().code, ErrorCode::limit_exceeded) << r.error().message;
  for (const char* part : {"bomb.3mf", "'3D/3dmodel.model'", "1000000000000 triangles", "limit of 100000000",
                           "line 21 (object 13, 1000000000000 triangles)"})
    EXPECT_NE(r.error().message.find(part), std::string::npos) << part << " in " << r.error().message;
  EXPECT_LT(counted.peak_bytes(), 100'000u);

  // Under a raised bound the same file is read: the bound is what refused it.
  MeshReadOptions wide;
  wide.max_triangles = 10'000'000;
  auto smaller = parse_3mf(nested_components(6, 10), "nested.3mf", wide);
  ASSERT_TRUE(smaller) << smaller.error().message;
  EXPECT_EQ(smaller->triangle_count(), 1'000'000u);
  MeshReadOptions tight;
  tight.max_triangles = 999'999;
  auto refused = parse_3mf(nested_components(6, 10), "nested.3mf", tight);
  ASSERT_FALSE(refused);
  EXPECT_EQ(refused.error().code, ErrorCode::limit_exceeded);
}

TEST(ReadLimits, ComponentCountsSaturateInsteadOfWrapping) {
  // 30 levels of 10 = 10^30 triangles, beyond 64 bits: "more than", not a wrapped count that
  // could pass. 40 levels nest deeper than 32: the nesting error, as before.
  auto deep = parse_3mf(nested_components(30, 10), "huge.3mf");
  ASSERT_FALSE(deep);
  EXPECT_EQ(deep.error().code, ErrorCode::limit_exceeded);
  EXPECT_NE(deep.error().message.find("more than 18446744073709551614 triangles"), std::string::npos)
      << deep.error().message;
  auto cycle = parse_3mf(nested_components(40, 2), "deep.3mf");
  ASSERT_FALSE(cycle);
  EXPECT_NE(cycle.error().message.find("nest deeper than 32"), std::string::npos) << cycle.error().message;
}

// Bytes allocated while reading a build of n copies of one triangle, per byte of the soup.
double allocated_per_soup_byte(const std::vector<std::byte>& zip, std::size_t triangles) {
  AllocationScope counted;
  auto soup = parse_3mf(zip, "copies.3mf");
  EXPECT_TRUE(soup) << soup.error().message;
  if (!soup) return 0.0;
  EXPECT_EQ(soup->triangle_count(), triangles);
  return static_cast<double>(counted.total_bytes()) / static_cast<double>(3 * sizeof(Eigen::Vector3f) * triangles);
}

TEST(ReadLimits, BuildItemsAndComponentInstancesCostLinearAllocation) {
  // Each instance used to reserve exactly the soup's new size, copying the whole soup: n²/2
  // corner copies (20,000 items took 33 s). Now the soup is allocated once.
  std::string items;
  for (int i = 0; i < 5000; ++i) items += fmt::format("<item objectid=\"1\" transform=\"1 0 0 0 1 0 0 0 1 {} 0 0\"/>\n", i);
  const auto many_items = package(model(kTriangleObject, items));
  // What the file itself costs (its text, 5000 build items) is some 15 bytes of allocation per
  // soup byte here; quadratic copying would be ~2500.
  EXPECT_LT(allocated_per_soup_byte(many_items, 5000), 30.0);
  EXPECT_LT(allocated_per_soup_byte(nested_components(4, 14), 14 * 14 * 14 * 14), 3.0);
}

// A one-triangle model padded with 24 MiB of whitespace: it deflates 1000:1.
const std::string& padded_model() {
  static const std::string xml = model(kTriangleObject + std::string(24 << 20, ' '), "<item objectid=\"1\"/>\n");
  return xml;
}

TEST(ReadLimits, AZipBombIsRefusedBeforeInflating) {
  const std::string& xml = padded_model();
  const auto zip = deflated_package(xml);
  ASSERT_LT(zip.size(), 40'000u);
  AllocationScope counted;
  auto r = parse_3mf(zip, "bomb.3mf");
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::limit_exceeded) << r.error().message;
  for (std::string part : {std::string("bomb.3mf"), std::string("zip entry '3D/3dmodel.model'"),
                           fmt::format("declares {} bytes inflated from", xml.size()), std::string("over the limit of"),
                           std::string("100:1")})
    EXPECT_NE(r.error().message.find(part), std::string::npos) << part << " in " << r.error().message;
  EXPECT_LT(counted.peak_bytes(), 1u << 20) << "nothing is inflated";

  // Allowed a higher ratio, the same package reads: the limit alone refused it.
  MeshReadOptions generous;
  generous.max_inflate_ratio = 2000;
  auto allowed = parse_3mf(zip, "bomb.3mf", generous);
  ASSERT_TRUE(allowed) << allowed.error().message;
  EXPECT_EQ(allowed->triangle_count(), 1u);
}

TEST(ReadLimits, InflationStopsAtTheDeclaredSizeInsteadOfAllocatingIt) {
  // Declared 1 MiB, inflates to 24 MiB: stopped one byte past 1 MiB.
  {
    const auto liar = deflated_package(padded_model(), 1 << 20);
    AllocationScope counted;
    auto r = parse_3mf(liar, "liar.3mf");
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().code, ErrorCode::parse_error) << r.error().message;
    EXPECT_NE(r.error().message.find("inflates past its declared 1048576 bytes"), std::string::npos)
        << r.error().message;
    EXPECT_LT(counted.peak_bytes(), 4u << 20);
  }
  // Declared 16 MiB (the most a small entry may, whatever its ratio), holding 20 kB: the buffer
  // grows with the output instead of starting at the declared size.
  std::mt19937 rng(7);
  std::string noise(20'000, ' ');
  for (char& c : noise) c = static_cast<char>(rng());  // incompressible: ~20 kB deflated
  const auto short_entry = deflated_package(noise, 16 << 20);
  AllocationScope counted;
  auto r = parse_3mf(short_entry, "short.3mf");
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("does not inflate to its declared 16777216 bytes"), std::string::npos)
      << r.error().message;
  EXPECT_LT(counted.peak_bytes(), 1u << 20);
}

}  // namespace
}  // namespace lamina
