// The rack (issue 17, item 5): `lamina plan bowl.stl --stock-file examples/remnants.toml` failed
// at nesting with "not enough 5 mm sheets: 2 in stock". Counts and sheet sizes are constraints of
// the layering: a stack uses no more layers of a thickness than the rack holds, no layer of a
// thickness whose sheets it does not fit, and a rack that cannot make the stack is one clear
// error (stock_exhausted) naming the thicknesses and how high it reaches.
#include "layering_checks.hpp"
#include "mesh_soups.hpp"
#include "revolve.hpp"

#include <lamina/core/layering.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <functional>
#include <map>
#include <vector>

namespace lamina {
namespace {

using layering_test::build;
using layering_test::expect_well_formed;
using layering_test::stock_params;
using test_shapes::revolve;

std::map<double, int> layers_per_thickness(const Layering& l) {
  std::map<double, int> n;
  for (const LayerSpan& s : l.layers) ++n[s.thickness_mm];
  return n;
}

ThicknessSupply at_most(double t, int layers) {
  ThicknessSupply s;
  s.thickness_mm = t;
  s.max_layers = layers;
  return s;
}

// Fewest layers of {1, 2.5, 5, 10} whose sum is in [h, h + 0.5] with at most caps[t] of each
// thickness, a top within the tolerance first (a box's walls are vertical: every layer is exact
// but the last, which is as far out as it ends above the box).
int fewest_layers_by_search(double h, double tol, const std::map<double, int>& caps) {
  const std::vector<double> t{1.0, 2.5, 5.0, 10.0};
  std::pair<int, int> best{1 << 30, 1 << 30};  // (top out of tolerance, layers)
  std::function<void(std::size_t, double, int)> go = [&](std::size_t i, double sum, int count) {
    if (i == t.size()) {
      if (sum >= h - 1e-9 && sum <= h + 0.5 + 1e-9) best = std::min(best, {sum - h > tol + 1e-9 ? 1 : 0, count});
      return;
    }
    const int cap = caps.count(t[i]) ? caps.at(t[i]) : 1000;
    for (int k = 0; k <= cap && sum + k * t[i] <= h + 0.5 + 1e-9; ++k) go(i + 1, sum + k * t[i], count + k);
  };
  go(0, 0.0, 0);
  return best.second;
}

TEST(LayeringSupply, CountsOfTheRackBoundEachThicknessAndTheDpStaysOptimal) {
  const Mesh mesh = build(mesh_test::box({0, 0, 0}, {30, 20, 43.0f}));
  for (auto method : {LayeringMethod::optimal, LayeringMethod::greedy}) {
    auto p = stock_params(method);
    p.tolerance_mm = 0.2;
    auto free_stack = choose_layers(mesh, p);
    ASSERT_TRUE(free_stack.has_value()) << free_stack.error().message;
    ASSERT_GE(layers_per_thickness(*free_stack)[10.0], 2) << "the test needs a stack the caps change";

    const std::map<double, int> caps{{10.0, 1}, {5.0, 2}};
    p.supply = {at_most(10.0, 1), at_most(5.0, 2)};
    auto r = choose_layers(mesh, p);
    ASSERT_TRUE(r.has_value()) << r.error().message;
    expect_well_formed(*r, p);
    const auto used = layers_per_thickness(*r);
    for (const auto& [t, cap] : caps) EXPECT_LE(used.count(t) ? used.at(t) : 0, cap) << t << " mm";
    if (method == LayeringMethod::optimal) {
      EXPECT_EQ(static_cast<int>(r->layers.size()), fewest_layers_by_search(43.0, p.tolerance_mm, caps));
    }
  }
}

TEST(LayeringSupply, ALayerIsOnlyCutFromSheetsItFits) {
  // A Ø100 base 10 mm high under a Ø20 post: 10 mm sheets of 30 x 30 mm only take the post.
  const Mesh mesh = build(revolve({{0, 0}, {50, 0}, {50, 10}, {10, 10}, {10, 40}, {0, 40}}, 64));
  auto p = stock_params();
  p.tolerance_mm = 0.2;
  ThicknessSupply small = at_most(10.0, -1);
  small.rooms = {{30.0, 30.0}};
  p.supply = {small};
  auto r = choose_layers(mesh, p);
  ASSERT_TRUE(r.has_value()) << r.error().message;
  expect_well_formed(*r, p);
  for (const LayerSpan& s : r->layers) {
    if (s.thickness_mm == 10.0) {
      EXPECT_GE(s.z_bottom_mm, 10.0 - 1e-9) << "a 10 mm layer holds part of the base";
    }
  }
  EXPECT_GE(layers_per_thickness(*r)[10.0], 2) << "the post is still cut from 10 mm sheets";
}

TEST(LayeringSupply, ARackThatCannotMakeTheStackIsOneErrorNamingWhatRunsOut) {
  const Mesh mesh = build(mesh_test::box({0, 0, 0}, {30, 20, 43.0f}));
  for (auto method : {LayeringMethod::optimal, LayeringMethod::greedy}) {
    auto p = stock_params(method);
    p.thicknesses_mm = {5.0, 10.0};
    p.supply = {at_most(10.0, 2), at_most(5.0, 2)};  // 30 mm of 43
    auto r = choose_layers(mesh, p);
    ASSERT_FALSE(r.has_value());
    EXPECT_EQ(r.error().code, ErrorCode::stock_exhausted);
    EXPECT_NE(r.error().message.find("10 mm: at most 2 layer(s)"), std::string::npos) << r.error().message;
    EXPECT_NE(r.error().message.find("5 mm: at most 2 layer(s)"), std::string::npos) << r.error().message;
    EXPECT_NE(r.error().message.find("reaches 30.000 mm"), std::string::npos) << r.error().message;
  }
}

TEST(LayeringSupply, ASupplyThatLimitsNothingChangesNothing) {
  const Mesh mesh = build(revolve({{0, 0}, {30, 0}, {40, 20}, {25, 35}, {0, 35}}, 64));
  auto p = stock_params();
  p.tolerance_mm = 0.2;
  auto plain = choose_layers(mesh, p);
  ThicknessSupply roomy = at_most(2.5, 1000);
  roomy.rooms = {{1000.0, 1000.0}};
  p.supply = {roomy};
  auto limited = choose_layers(mesh, p);
  ASSERT_TRUE(plain.has_value() && limited.has_value());
  ASSERT_EQ(plain->layers.size(), limited->layers.size());
  for (std::size_t i = 0; i < plain->layers.size(); ++i) {
    EXPECT_EQ(plain->layers[i].thickness_mm, limited->layers[i].thickness_mm);
    EXPECT_EQ(plain->layers[i].estimated_deviation_mm, limited->layers[i].estimated_deviation_mm);
  }
}

}  // namespace
}  // namespace lamina
