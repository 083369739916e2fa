// Parameter validation: every parameter outside its domain is an invalid_argument with a message
// naming it; a model without height cannot be layered.
#include "layering_checks.hpp"
#include "mesh_soups.hpp"

#include <lamina/core/layering.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

namespace lamina {
namespace {

using layering_test::build;
using layering_test::stock_params;

const Mesh& cube() {
  static const Mesh m = build(mesh_test::box({0, 0, 0}, {20, 20, 10}));
  return m;
}

void expect_invalid(const LayeringParams& p, const std::string& mentions) {
  auto r = choose_layers(cube(), p);
  ASSERT_FALSE(r.has_value());
  EXPECT_EQ(r.error().code, ErrorCode::invalid_argument);
  EXPECT_NE(r.error().message.find(mentions), std::string::npos) << r.error().message;
}

TEST(LayeringParams, ValidParametersLayer) {
  auto r = choose_layers(cube(), stock_params());
  ASSERT_TRUE(r.has_value()) << r.error().message;
  EXPECT_FALSE(r->layers.empty());
}

TEST(LayeringParams, EmptyThicknessListIsRejected) {
  auto p = stock_params();
  p.thicknesses_mm.clear();
  expect_invalid(p, "thickness");
}

TEST(LayeringParams, NegativeZeroAndNonFiniteThicknessesAreRejected) {
  for (double bad : {-1.0, 0.0, std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
    SCOPED_TRACE(bad);
    auto p = stock_params();
    p.thicknesses_mm.push_back(bad);
    expect_invalid(p, "thickness #5");
  }
}

TEST(LayeringParams, SubSliceMustBePositiveAndFinite) {
  for (double bad : {0.0, -0.5, std::numeric_limits<double>::quiet_NaN()}) {
    SCOPED_TRACE(bad);
    auto p = stock_params();
    p.sub_slice_mm = bad;
    expect_invalid(p, "sub_slice_mm");
  }
}

TEST(LayeringParams, BondToleranceAndGreedyLimitsAreChecked) {
  auto p = stock_params();
  p.bond_mm = -0.1;
  expect_invalid(p, "bond_mm");
  p = stock_params();
  p.bond_mm = std::numeric_limits<double>::quiet_NaN();
  expect_invalid(p, "bond_mm");
  p = stock_params();
  p.tolerance_mm = 0.0;
  expect_invalid(p, "tolerance_mm");
  p = stock_params();
  p.tolerance_mm = std::numeric_limits<double>::infinity();
  expect_invalid(p, "tolerance_mm");
  p = stock_params();
  p.greedy_area_deviation = -0.1;
  expect_invalid(p, "greedy_area_deviation");
  p = stock_params();
  p.greedy_triangle_area_mm2 = std::numeric_limits<double>::quiet_NaN();
  expect_invalid(p, "greedy_triangle_area_mm2");
  p = stock_params();
  p.fit.tilt_max_rad = 2.0;
  expect_invalid(p, "tilt_max_rad");
}

TEST(LayeringParams, AbsurdGridIsRejectedNotAllocated) {
  auto p = stock_params();
  p.sub_slice_mm = 1e-9;  // 10 mm / 1e-9 mm = 1e10 grid lines
  expect_invalid(p, "grid lines");
}

TEST(LayeringParams, FlatModelHasNoHeightToLayer) {
  TriangleSoup s;
  mesh_test::add_tri(s, {0, 0, 0}, {10, 0, 0}, {0, 10, 0});
  mesh_test::add_tri(s, {0, 0, 0}, {0, 10, 0}, {10, 0, 0});
  auto mesh = build_mesh(s, MeshParams{});
  ASSERT_TRUE(mesh.has_value());
  auto r = choose_layers(*mesh, stock_params());
  ASSERT_FALSE(r.has_value());
  EXPECT_EQ(r.error().code, ErrorCode::invalid_argument);
}

TEST(LayeringParams, MethodNames) {
  EXPECT_STREQ(layering_method_name(LayeringMethod::optimal), "optimal");
  EXPECT_STREQ(layering_method_name(LayeringMethod::greedy), "greedy");
}

TEST(LayeringParams, ThicknessOrderAndDuplicatesDoNotMatter) {
  auto a = stock_params();
  auto b = stock_params();
  b.thicknesses_mm = {10.0, 1.0, 5.0, 2.5, 5.0, 1.0};
  auto ra = choose_layers(cube(), a);
  auto rb = choose_layers(cube(), b);
  ASSERT_TRUE(ra && rb);
  ASSERT_EQ(ra->layers.size(), rb->layers.size());
  for (std::size_t i = 0; i < ra->layers.size(); ++i) {
    EXPECT_EQ(ra->layers[i].z_bottom_mm, rb->layers[i].z_bottom_mm);
    EXPECT_EQ(ra->layers[i].thickness_mm, rb->layers[i].thickness_mm);
  }
}

}  // namespace
}  // namespace lamina

namespace lamina {
namespace {

// Issue 16, item 11: `--stock 1e10` crashed the planner, `--stock 0.001` took 2.6 GB in 90 s.
// The stock is checked against the model before anything is sliced.
TEST(LayeringParams, StockIsCheckedAgainstTheModel) {
  auto p = stock_params();
  p.thicknesses_mm = {1e10};
  expect_invalid(p, "every stock sheet is thicker than the part: the thinnest is 10000000000 mm, the part 10.000 mm");
  p.thicknesses_mm = {0.001};
  expect_invalid(p, "stock thickness 0.001 mm is thinner than half the sub-slice spacing (0.5 mm)");
  p.thicknesses_mm = {0.001};
  p.sub_slice_mm = 0.001;
  const Mesh tall = build(mesh_test::box({0, 0, 0}, {20, 20, 20}));
  auto r = choose_layers(tall, p);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("the part (20.000 mm) in 0.001 mm sheets would be 20000 layers, more than 10000"),
            std::string::npos)
      << r.error().message;
}

TEST(LayeringParams, SheetsThickerThanThePartAreLeftOutAndSaid) {
  auto p = stock_params();
  p.thicknesses_mm = {2.5, 5, 1e10, 20};
  auto r = choose_layers(cube(), p);
  ASSERT_TRUE(r) << r.error().message;
  for (const LayerSpan& l : r->layers) EXPECT_LE(l.thickness_mm, 5.0);
  bool said = false;
  for (const auto& w : r->warnings) said = said || w.find("not used: 10000000000, 20 mm") != std::string::npos;
  EXPECT_TRUE(said) << ::testing::PrintToString(r->warnings);
}

}  // namespace
}  // namespace lamina
