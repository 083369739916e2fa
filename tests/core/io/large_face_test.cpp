// OBJ faces with many corners (issue 16, item 12): a 100,000-corner face took 60 s of ear clipping,
// every ear tested against every corner. Large faces now go through the indexed clipper: the
// work is counted (ear tests and the corners looked at), not timed, and must stay about linear.
#include "geometry/ear_clipping.hpp"
#include "io_test_util.hpp"
#include "lamina/core/mesh_io.hpp"
#include "lamina/core/polygon.hpp"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <numbers>
#include <random>
#include <string>

namespace lamina {
namespace {

using Ring = Polygon2;

Ring circle(int n) {
  Ring r;
  for (int i = 0; i < n; ++i) r.emplace_back(std::cos(2 * std::numbers::pi * i / n), std::sin(2 * std::numbers::pi * i / n));
  return r;
}

Ring star(int n) {
  Ring r = circle(n);
  for (int i = 1; i < n; i += 2) r[static_cast<std::size_t>(i)] *= 0.5;
  return r;
}

// Teeth 10 tall on a base: half the corners reflex, long thin ears.
Ring comb(int teeth) {
  Ring r{{0.0, -1.0}, {teeth * 1.0, -1.0}};
  for (int k = teeth - 1; k >= 0; --k) {
    r.emplace_back(k + 0.5, 0.0);
    r.emplace_back(k + 0.5, 10.0);
    r.emplace_back(k, 10.0);
    r.emplace_back(k, 0.0);
  }
  return r;
}

// A strip wound four times round: ears only along its outer side.
Ring spiral(int n) {
  Ring outer, inner;
  for (int i = 0; i < n / 2; ++i) {
    const double t = 8 * std::numbers::pi * i / (n / 2);
    outer.emplace_back((1.5 + t) * std::cos(t), (1.5 + t) * std::sin(t));
    inner.emplace_back((1.0 + t) * std::cos(t), (1.0 + t) * std::sin(t));
  }
  Ring r(inner.begin(), inner.end());
  r.insert(r.end(), outer.rbegin(), outer.rend());
  return r;
}

double area(const Ring& r) { return signed_area_mm2(r); }

// The ring in the plane z = 3 (counter-clockwise, as a face seen from +z).
std::vector<Eigen::Vector3f> in_3d(Ring r) {
  if (area(r) < 0) std::reverse(r.begin(), r.end());
  std::vector<Eigen::Vector3f> out;
  for (const auto& p : r) out.emplace_back(static_cast<float>(p.x()), static_cast<float>(p.y()), 3.0f);
  return out;
}

TEST(LargeFaces, EarClippingWorkIsAboutLinear) {
  const std::pair<const char*, Ring> shapes[] = {
      {"circle", circle(20000)}, {"star", star(20000)}, {"comb", comb(5000)}, {"spiral", spiral(20000)}};
  for (const auto& [what, ring] : shapes) {
    const auto corners = in_3d(ring);
    const std::size_t n = corners.size();
    std::vector<std::array<std::uint32_t, 3>> tris;
    geometry_detail::EarClippingScratch scratch;
    ASSERT_TRUE(geometry_detail::triangulate_polygon(corners, tris, scratch)) << what;
    ASSERT_EQ(tris.size(), n - 2) << what;
    // Each ear tested against every corner: n²/2 = 2·10^8 steps here. n log n allows ~300·n.
    EXPECT_LT(scratch.steps, 20 * n * std::bit_width(n)) << what << ": " << scratch.steps / n << " steps a corner";
    double sum = 0.0;
    int flipped = 0;
    for (const auto& t : tris) {
      const Eigen::Vector3f a = corners[t[0]], b = corners[t[1]], c = corners[t[2]];
      const double z = static_cast<double>((b - a).cross(c - a).z());
      sum += 0.5 * z;
      flipped += z < 0.0;
    }
    EXPECT_EQ(flipped, 0) << what;
    EXPECT_NEAR(sum, std::abs(area(ring)), 1e-4 * std::abs(area(ring))) << what;
  }
}

TEST(LargeFaces, AHundredThousandCornerFaceReads) {
  std::string text;
  for (const auto& p : star(100000)) text += fmt::format("v {:.9g} {:.9g} 0\n", p.x(), p.y());
  text += "f";
  for (int i = 1; i <= 100000; ++i) text += fmt::format(" {}", i);
  auto soup = parse_obj(text + "\n", "star.obj");
  ASSERT_TRUE(soup) << soup.error().message;
  EXPECT_EQ(soup->triangle_count(), 99998u);
  EXPECT_NEAR(test::unsigned_area(*soup), area(star(100000)), 1e-3);
}

TEST(LargeFaces, AFaceOfNoiseIsRefusedNamingItsLine) {
  // 20,000 corners in random order cross themselves everywhere: no ear holds, and every forced
  // cut would walk the ring. Past the step budget the reader stops with an error.
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::string text = "# noise\n";
  const int n = 20000;
  for (int i = 0; i < n; ++i) text += fmt::format("v {:.6f} {:.6f} {:.6f}\n", u(rng), u(rng), 0.01 * u(rng));
  text += "f";
  for (int i = 1; i <= n; ++i) text += fmt::format(" {}", i);
  auto soup = parse_obj(text + "\n", "noise.obj");
  if (soup) GTEST_SKIP() << "the noise face was triangulated within the budget";
  EXPECT_EQ(soup.error().code, ErrorCode::limit_exceeded);
  EXPECT_NE(soup.error().message.find(fmt::format("noise.obj:{}: OBJ: the face of 20000 corners", n + 2)),
            std::string::npos)
      << soup.error().message;
}

}  // namespace
}  // namespace lamina
