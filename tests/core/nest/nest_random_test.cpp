// Seeded random parts (star-shaped polygons, often concave) through both methods; plus the time
// to nest 50 and 200 parts, printed (not asserted).
#include "nest_checks.hpp"

#include <gtest/gtest.h>

#include <random>

namespace lamina {
namespace {

using namespace nest_test;

std::vector<Part> random_parts(int n, unsigned seed, double thickness_a, double thickness_b) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> size(15.0, 120.0);
  std::uniform_real_distribution<double> jitter(0.45, 1.0);
  std::uniform_real_distribution<double> where(-500.0, 500.0);
  std::uniform_int_distribution<int> corners(3, 14);
  std::vector<Part> parts;
  for (int i = 0; i < n; ++i) {
    const int k = corners(rng);
    const double rx = size(rng);
    const double ry = size(rng);
    const double cx = where(rng);
    const double cy = where(rng);
    Polygon2 ring;
    for (int c = 0; c < k; ++c) {
      const double a = 2 * std::numbers::pi * (c + 0.3 * jitter(rng)) / k;
      const double r = jitter(rng);
      ring.emplace_back(cx + rx * r * std::cos(a), cy + ry * r * std::sin(a));
    }
    parts.push_back(make_part(ring, i % 3 == 0 ? thickness_b : thickness_a, 1 + i / 10, 1 + i % 10));
  }
  return parts;
}

Stock rack() {
  Stock s;
  s.sheets.push_back({3.0, 600, 1200, 3, "3 mm", ""});
  s.sheets.push_back({1.5, 500, 1000, 0, "1.5 mm", ""});
  s.sheets.push_back({3.0, 500, 1000, 0, "3 mm offcut", ""});
  return s;
}

class NestRandom : public ::testing::TestWithParam<NestMethod> {};

TEST_P(NestRandom, SeededRandomPolygons) {
  for (unsigned seed : {1u, 7u, 42u}) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    const std::vector<Part> parts = random_parts(80, seed, 1.5, 3.0);
    NestParams params;
    params.method = GetParam();
    params.spacing_mm = 5.0;
    params.margin_mm = 12.0;
    const Stock stock = rack();
    auto nest = nest_parts(parts, stock, params);
    ASSERT_TRUE(nest) << nest.error().message;
    const Summary s = check_nest(parts, stock, params, *nest);
    std::printf("[%s] seed %u, 80 random parts: %d sheets, mean utilisation %.3f\n", nest_method_name(GetParam()), seed,
                s.sheets, s.mean_utilisation);
  }
}

// Many parts at once: every placement still valid. (How long it takes is measured in
// bench/bench_cam, not here.)
TEST_P(NestRandom, FiftyAndTwoHundredRandomPartsNestValidly) {
  for (int n : {50, 200}) {
    const std::vector<Part> parts = random_parts(n, 2024u, 1.5, 1.5);
    NestParams params;
    params.method = GetParam();
    const Stock stock = one_sheet_kind(1.5, 1250, 625);
    auto nest = nest_parts(parts, stock, params);
    ASSERT_TRUE(nest) << nest.error().message;
    const Summary sum = check_nest(parts, stock, params, *nest);
    std::printf("[%s] %d random parts on 1250 x 625: %d sheets, mean utilisation %.3f\n",
                nest_method_name(GetParam()), n, sum.sheets, sum.mean_utilisation);
  }
}

INSTANTIATE_TEST_SUITE_P(BothMethods, NestRandom, ::testing::Values(NestMethod::matrix, NestMethod::shape),
                         [](const auto& info) { return std::string(nest_method_name(info.param)); });

}  // namespace
}  // namespace lamina
