// Where the stack ends (issue 17, item 3): a 50 mm bowl planned 53.5 mm (its last 10 mm sheet
// estimated 0.121 mm and measured 3.750 mm), a 60 mm bracket planned 66 mm with 1 mm sheets in
// stock, and a bracket's flat face fell inside a layer. The stack must end at the model's top
// within half the thinnest sheet unless the stock cannot (then a warning says so), the distance
// to the top is part of the last layer's estimate, and a flat face a boundary can meet is met.
#include "layering_checks.hpp"
#include "mesh_soups.hpp"
#include "revolve.hpp"

#include <lamina/core/layering.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace lamina {
namespace {

using layering_test::build;
using layering_test::expect_well_formed;
using layering_test::has_warning;
using layering_test::stock_params;
using test_shapes::revolve;

// An open cup standing on its base, `h` high: the wall flares from r 20 at the bottom to r 45 at
// the rim (26.6° from vertical, within the tilt limit), 3 mm thick, a 3 mm floor; the rim is a
// flat ring at the top.
Mesh cup(double h) {
  const double flare = 25.0 / 50.0;
  return build(revolve({{0, 0}, {20, 0}, {20 + flare * h, h}, {17 + flare * h, h}, {17 + flare * 3, 3}, {0, 3}}, 96));
}

double stack_top(const Layering& l) { return l.layers.back().z_top_mm() - l.layers.front().z_bottom_mm; }

TEST(LayeringTop, CupEndsWithinHalfTheThinnestSheetOfItsRim) {
  for (double h : {48.7, 50.0, 51.3}) {
    SCOPED_TRACE(::testing::Message() << "cup " << h << " mm");
    const Mesh mesh = cup(h);
    auto p = stock_params();
    p.tolerance_mm = 0.2;
    auto r = choose_layers(mesh, p);
    ASSERT_TRUE(r.has_value()) << r.error().message;
    expect_well_formed(*r, p);
    EXPECT_GE(stack_top(*r), h - 1e-6) << "outside: the whole cup is kept";
    EXPECT_LE(stack_top(*r), h + 0.5 + 1e-6) << "a 10 mm sheet was used past the rim";
    EXPECT_FALSE(has_warning(*r, "cannot end the stack"));
  }
}

TEST(LayeringTop, BoxNotASumOfStockEndsAtItsTopWhenThinSheetsAreStocked) {
  // 53.3 mm with {1, 2.5, 10}: five 10 mm, one 2.5 and one 1 end 0.2 mm above the top.
  const Mesh mesh = build(mesh_test::box({0, 0, 0}, {30, 20, 53.3f}));
  auto p = stock_params();
  p.thicknesses_mm = {1.0, 2.5, 10.0};
  p.tolerance_mm = 0.25;
  auto r = choose_layers(mesh, p);
  ASSERT_TRUE(r.has_value()) << r.error().message;
  expect_well_formed(*r, p);
  EXPECT_NEAR(stack_top(*r), 53.5, 1e-4);
  EXPECT_EQ(r->layers.size(), 7u);
  EXPECT_TRUE(r->layers.back().within_tolerance);
  EXPECT_NEAR(r->layers.back().estimated_deviation_mm, 0.2, 1e-3) << "the overshoot is the last layer's estimate";

  // At 0.1 no stack ends within the tolerance: still the one 0.2 mm over (not six 10 mm sheets
  // 6.7 mm over, which would be one layer fewer), and a warning says so.
  p.tolerance_mm = 0.1;
  auto tight = choose_layers(mesh, p);
  ASSERT_TRUE(tight.has_value()) << tight.error().message;
  expect_well_formed(*tight, p);
  EXPECT_NEAR(stack_top(*tight), 53.5, 1e-4);
  EXPECT_TRUE(has_warning(*tight, "no stack of this stock ends within the tolerance"));
}

TEST(LayeringTop, StockThatCannotEndNearTheTopSaysSo) {
  // Only 10 mm sheets for 53.3 mm: 60 mm is the nearest an outside stack can end, 6.7 mm over.
  const Mesh mesh = build(mesh_test::box({0, 0, 0}, {30, 20, 53.3f}));
  auto p = stock_params();
  p.thicknesses_mm = {10.0};
  auto r = choose_layers(mesh, p);
  ASSERT_TRUE(r.has_value()) << r.error().message;
  expect_well_formed(*r, p);
  EXPECT_NEAR(stack_top(*r), 60.0, 1e-4);
  EXPECT_FALSE(r->layers.back().within_tolerance);
  EXPECT_FALSE(r->layers.back().shortfall) << "the surface is exact: only where it ends is out";
  EXPECT_TRUE(has_warning(*r, "cannot end the stack within half its thinnest sheet (5 mm)")) << r->warnings.front();
}

TEST(LayeringTop, InsideAndMixedEndWhereTheirSideAllows) {
  const Mesh mesh = build(mesh_test::box({0, 0, 0}, {30, 20, 53.3f}));
  for (CutSide side : {CutSide::inside, CutSide::mixed}) {
    SCOPED_TRACE(cut_side_name(side));
    auto p = stock_params();
    p.thicknesses_mm = {1.0, 2.5, 10.0};
    p.fit.side = side;
    p.tolerance_mm = 0.4;
    auto r = choose_layers(mesh, p);
    ASSERT_TRUE(r.has_value()) << r.error().message;
    expect_well_formed(*r, p);
    // inside: 53 (0.3 below, nothing beyond the model); mixed: 53 or 53.5, the nearer is 53.5.
    EXPECT_NEAR(stack_top(*r), side == CutSide::inside ? 53.0 : 53.5, 1e-4);
  }
}

TEST(LayeringTop, FlatFaceABoundaryCanMeetIsMet) {
  // An L bracket standing on its base: base 40 × 30 × 8, upright 40 × 8 up to 60. The base's top
  // face (z = 8) inside a layer stands up to the layer's thickness proud of the cut edge; 8 mm is
  // a sum of the stock, so a boundary lies there.
  const Mesh mesh = build(mesh_test::append(mesh_test::box({0, 0, 0}, {40, 30, 8}),
                                            mesh_test::box({0, 0, 8}, {40, 8, 60})));
  auto p = stock_params();
  p.tolerance_mm = 0.2;
  auto r = choose_layers(mesh, p);
  ASSERT_TRUE(r.has_value()) << r.error().message;
  expect_well_formed(*r, p);
  bool boundary_at_face = false;
  for (const auto& l : r->layers) {
    boundary_at_face |= std::abs(l.z_top_mm() - 8.0) < 1e-6;
    EXPECT_TRUE(l.within_tolerance) << "layer at z " << l.z_bottom_mm;
  }
  EXPECT_TRUE(boundary_at_face);
  EXPECT_NEAR(stack_top(*r), 60.0, 1e-4);
}

}  // namespace
}  // namespace lamina
