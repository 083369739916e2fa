// The bevel plan's facets by height (bevel/facets_by_z.hpp) against a scan of every facet: the
// same facets, in the same (ascending) order, for slabs on and between bin edges, slabs outside
// the mesh, and a mesh of full-height strips that makes the bins coarser.
#include "bevel/facets_by_z.hpp"

#include <gtest/gtest.h>

#include <limits>
#include <random>
#include <utility>

namespace lamina {
namespace {

using bevel_detail::FacetsByZ;

std::vector<std::uint32_t> scanned(const Mesh& mesh, double zb, double zt) {
  std::vector<std::uint32_t> out;
  for (std::size_t f = 0; f < mesh.faces.size(); ++f) {
    double lo = 1e300, hi = -1e300;
    for (int k = 0; k < 3; ++k) {
      const double z = mesh.vertices[static_cast<std::size_t>(mesh.faces[f][static_cast<std::size_t>(k)])].z();
      lo = std::min(lo, z);
      hi = std::max(hi, z);
    }
    if (!(hi < zb || lo > zt)) out.push_back(static_cast<std::uint32_t>(f));
  }
  return out;
}

// Triangles with corners at random heights in [0, height], each `tall` of them a full-height strip.
Mesh random_triangles(int count, double height, int tall_every, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> z(0.0, height), xy(-10.0, 10.0), small(0.0, 0.7);
  Mesh m;
  for (int i = 0; i < count; ++i) {
    const double z0 = z(rng);
    const bool tall = tall_every > 0 && i % tall_every == 0;
    const int v = static_cast<int>(m.vertices.size());
    m.vertices.emplace_back(xy(rng), xy(rng), tall ? 0.0 : z0);
    m.vertices.emplace_back(xy(rng), xy(rng), tall ? height : z0 + small(rng));
    m.vertices.emplace_back(xy(rng), xy(rng), tall ? height : z0 - small(rng));
    m.faces.push_back({v, v + 1, v + 2});
  }
  return m;
}

void expect_same_as_scan(const Mesh& m, double bin_mm, double height) {
  const FacetsByZ index(m, bin_mm);
  std::vector<std::uint32_t> got;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> at(-1.0, height + 1.0), thick(0.0, 12.0);
  for (int q = 0; q < 300; ++q) {
    // Every fifth slab starts on a bin edge, where a facet touching it must still count.
    const double zb = q % 5 == 0 ? std::round(at(rng) / bin_mm) * bin_mm : at(rng);
    const double zt = zb + (q % 7 == 0 ? 0.0 : thick(rng));
    index.in_slab(zb, zt, got);
    ASSERT_EQ(got, scanned(m, zb, zt)) << "slab " << zb << " .. " << zt;
  }
}

TEST(FacetsByZ, GivesWhatAScanOfEveryFacetGivesInItsOrder) {
  expect_same_as_scan(random_triangles(5000, 100.0, 0, 1), 0.5, 100.0);
}

TEST(FacetsByZ, SlabsFarFromTheMeshHoldNoFacet) {
  const Mesh m = random_triangles(500, 100.0, 0, 3);
  const FacetsByZ index(m, 0.5);
  std::vector<std::uint32_t> got;
  index.in_slab(-1e15, -1e14, got);
  EXPECT_TRUE(got.empty());
  index.in_slab(1e14, 1e15, got);
  EXPECT_TRUE(got.empty());
  index.in_slab(-1e15, 1e15, got);
  EXPECT_EQ(got.size(), m.faces.size());
}

TEST(FacetsByZ, FullHeightStripsMakeTheBinsCoarserAndChangeNothing) {
  // Every other facet spans the whole height: listed in each of 200 bins, that would be 100
  // entries per facet; the index coarsens its bins instead.
  expect_same_as_scan(random_triangles(4000, 100.0, 2, 2), 0.5, 100.0);
}

TEST(FacetsByZ, AnEmptyMeshHasNoFacetsInAnySlab) {
  const FacetsByZ index(Mesh{}, 0.5);
  std::vector<std::uint32_t> got{1, 2};
  index.in_slab(0.0, 10.0, got);
  EXPECT_TRUE(got.empty());
}

// The index keeps each facet's heights as floats rounded outwards: slabs that end exactly on a
// facet's lowest or highest point, or a double's step beside it (far below a float's), must
// give what the doubles give.
TEST(FacetsByZ, SlabsEndingOnAFacetsHeightOrADoublesStepBesideIt) {
  const Mesh m = random_triangles(2000, 100.0, 0, 4);
  const FacetsByZ index(m, 0.5);
  std::vector<std::uint32_t> got;
  const double inf = std::numeric_limits<double>::infinity();
  for (std::size_t f = 0; f < m.faces.size(); f += 7) {
    for (const auto& corner : m.faces[f]) {
      const double z = m.vertices[static_cast<std::size_t>(corner)].z();
      for (const double end : {std::nextafter(z, -inf), z, std::nextafter(z, inf)}) {
        for (const auto& [zb, zt] : {std::pair{end, end + 0.25}, std::pair{end - 0.25, end}, std::pair{end, end}}) {
          index.in_slab(zb, zt, got);
          ASSERT_EQ(got, scanned(m, zb, zt)) << "slab " << zb << " .. " << zt;
        }
      }
    }
  }
}

}  // namespace
}  // namespace lamina
