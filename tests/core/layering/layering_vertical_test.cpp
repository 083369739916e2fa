// Vertical walls (boxes, cylinders) can be cut exactly at any thickness: every layer's achievable
// deviation is zero, so the optimal layering is decided by the count and then the overshoot alone.
// A brute-force search over sheet sequences (independent of the estimator) gives both.
#include "layering_checks.hpp"
#include "mesh_soups.hpp"

#include <lamina/core/layering.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <vector>

namespace lamina {
namespace {

using layering_test::build;
using layering_test::expect_well_formed;
using layering_test::has_warning;
using layering_test::stock_params;

Mesh box_of_height(double h) { return build(mesh_test::box({0, 0, 0}, {20, 20, static_cast<float>(h)})); }

// Fewest sheets whose stack (sheets + bonds) reaches h, and the least overshoot among them.
struct Oracle {
  int count;
  double overshoot;
};
Oracle fewest_sheets(const std::vector<double>& t, double bond, double h) {
  std::set<long long> frontier{0};  // tops in nm (the stack below the next sheet, bond included)
  for (int k = 1; k < 1000; ++k) {
    std::set<long long> next;
    double best = INFINITY;
    for (long long start : frontier) {
      for (double th : t) {
        const double top = static_cast<double>(start) * 1e-6 + th;
        if (top >= h - 1e-9) {
          best = std::min(best, top - h);
        } else {
          next.insert(std::llround((top + bond) * 1e6));
        }
      }
    }
    if (std::isfinite(best)) return {k, best};
    frontier = std::move(next);
  }
  return {-1, 0};
}

TEST(LayeringVertical, BoxTenMillimetresIsOneTenMillimetreSheet) {
  const Mesh mesh = box_of_height(10);
  const auto p = stock_params();
  auto r = choose_layers(mesh, p);
  ASSERT_TRUE(r.has_value()) << r.error().message;
  expect_well_formed(*r, p);
  ASSERT_EQ(r->layers.size(), 1u);
  EXPECT_EQ(r->layers[0].thickness_mm, 10.0);
  EXPECT_EQ(r->layers[0].z_bottom_mm, 0.0);
  EXPECT_TRUE(r->layers[0].within_tolerance);
  EXPECT_LT(r->layers[0].estimated_deviation_mm, 1e-6) << "vertical walls are cut exactly";
  EXPECT_DOUBLE_EQ(r->model_height_mm, 10.0);
  EXPECT_DOUBLE_EQ(r->stack_height_mm, 10.0);
  EXPECT_TRUE(r->shortfalls.empty());
  EXPECT_FALSE(has_warning(*r, "taller"));
}

TEST(LayeringVertical, BoxTwelveMillimetresTakesTwoSheetsAndReportsTheOvershoot) {
  // No two sheets of {1, 2.5, 5, 10} sum to 12; three (10 + 1 + 1) do. Fewest layers first:
  // two sheets, and of those the least overshoot is 10 + 2.5 = 12.5.
  const Mesh mesh = box_of_height(12);
  const auto p = stock_params();
  auto r = choose_layers(mesh, p);
  ASSERT_TRUE(r.has_value()) << r.error().message;
  expect_well_formed(*r, p);
  ASSERT_EQ(r->layers.size(), 2u);
  std::vector<double> used{r->layers[0].thickness_mm, r->layers[1].thickness_mm};
  std::sort(used.begin(), used.end());
  EXPECT_EQ(used, (std::vector<double>{2.5, 10.0}));
  EXPECT_DOUBLE_EQ(r->model_height_mm, 12.0);
  EXPECT_DOUBLE_EQ(r->stack_height_mm, 12.5);
  EXPECT_NEAR(r->stack_height_mm - r->model_height_mm, 0.5, 1e-9);
  EXPECT_TRUE(has_warning(*r, "0.500 mm taller"));
  for (const auto& l : r->layers) {
    EXPECT_TRUE(l.within_tolerance);
    EXPECT_LT(l.estimated_deviation_mm, 1e-6) << "the sheet above the model's top is overshoot, not deviation";
  }
}

TEST(LayeringVertical, BondGapShiftsEveryLayer) {
  const Mesh mesh = box_of_height(12);
  auto p = stock_params();
  p.bond_mm = 0.2;
  auto r = choose_layers(mesh, p);
  ASSERT_TRUE(r.has_value()) << r.error().message;
  expect_well_formed(*r, p);
  ASSERT_EQ(r->layers.size(), 2u);
  EXPECT_NEAR(r->layers[1].z_bottom_mm, r->layers[0].thickness_mm + 0.2, 1e-12);
  double sheets = 0;
  for (const auto& l : r->layers) sheets += l.thickness_mm;
  EXPECT_NEAR(r->stack_height_mm, sheets + 0.2, 1e-12);
  EXPECT_NEAR(r->stack_height_mm, 12.7, 1e-12);
  EXPECT_TRUE(has_warning(*r, "bond gap")) << "0.2 mm puts the layers off the 0.5 mm grid";
}

TEST(LayeringVertical, FewestSheetsThenLeastOvershootMatchesBruteForce) {
  const std::vector<double> stock{1.0, 2.5, 5.0, 10.0};
  for (double bond : {0.0, 0.25, 0.3}) {
    for (double h : {3.0, 7.3, 10.0, 12.0, 17.5, 23.7, 31.2}) {
      SCOPED_TRACE(::testing::Message() << "h " << h << " bond " << bond);
      const Mesh mesh = box_of_height(h);
      auto p = stock_params();
      p.bond_mm = bond;
      auto r = choose_layers(mesh, p);
      ASSERT_TRUE(r.has_value()) << r.error().message;
      expect_well_formed(*r, p);
      // A sheet thicker than the whole part is never used (it is left out, and said).
      std::vector<double> usable;
      for (double t : stock)
        if (t <= r->model_height_mm) usable.push_back(t);
      const Oracle o = fewest_sheets(usable, bond, r->model_height_mm);
      EXPECT_EQ(static_cast<int>(r->layers.size()), o.count);
      EXPECT_NEAR(r->stack_height_mm - r->model_height_mm, o.overshoot, 1e-6);
      EXPECT_TRUE(r->shortfalls.empty());
      EXPECT_EQ(has_warning(*r, "taller"), o.overshoot > 1e-6);
    }
  }
}

TEST(LayeringVertical, GreedyAndOptimalAgreeOnVerticalWalls) {
  struct Case {
    const char* name;
    TriangleSoup soup;
  };
  const Case cases[] = {
      {"cylinder r15 h20", mesh_test::cylinder(15, 20, 96)},
      {"box 20x20x12", mesh_test::box({0, 0, 0}, {20, 20, 12})},
      {"box 30x10x25", mesh_test::box({-5, 3, 0}, {25, 13, 25})},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const Mesh mesh = build(c.soup);
    const auto po = stock_params(LayeringMethod::optimal);
    const auto pg = stock_params(LayeringMethod::greedy);
    auto opt = choose_layers(mesh, po);
    auto gr = choose_layers(mesh, pg);
    ASSERT_TRUE(opt && gr);
    expect_well_formed(*opt, po);
    expect_well_formed(*gr, pg);
    EXPECT_EQ(opt->layers.size(), gr->layers.size());
    EXPECT_NEAR(opt->stack_height_mm, gr->stack_height_mm, 1e-9);
    for (const auto& l : gr->layers) {
      EXPECT_TRUE(l.within_tolerance) << "vertical walls pass the area and triangle criteria";
      EXPECT_LT(l.estimated_deviation_mm, 1e-6);
    }
    // Greedy starts with the thickest sheet on vertical walls.
    EXPECT_EQ(gr->layers.front().thickness_mm, 10.0);
  }
}

TEST(LayeringVertical, TubeWithBoreIsStillExact) {
  // A hole: its stations look into the bore (normals away from the material), walls vertical.
  const Mesh mesh = build(test::tube(30, 12, 15, 64));
  const auto p = stock_params();
  auto r = choose_layers(mesh, p);
  ASSERT_TRUE(r.has_value());
  expect_well_formed(*r, p);
  EXPECT_EQ(r->layers.size(), 2u);  // 15 = 10 + 5
  EXPECT_DOUBLE_EQ(r->stack_height_mm, 15.0);
  for (const auto& l : r->layers) EXPECT_LT(l.estimated_deviation_mm, 1e-6);
}

}  // namespace
}  // namespace lamina
