// Matrix nesting: shelves of bounding boxes, 0° or 90°, spacing between boxes, margin at edges.
#include "nest_checks.hpp"

#include <gtest/gtest.h>

#include <numbers>

namespace lamina {
namespace {

using namespace nest_test;

NestParams matrix(double spacing = 5.0, double margin = 10.0) {
  NestParams p;
  p.method = NestMethod::matrix;
  p.spacing_mm = spacing;
  p.margin_mm = margin;
  return p;
}

TEST(NestMatrix, MethodNames) {
  EXPECT_STREQ(nest_method_name(NestMethod::matrix), "matrix");
  EXPECT_STREQ(nest_method_name(NestMethod::shape), "shape");
}

TEST(NestMatrix, PlacePointRotatesThenOffsets) {
  Placement pl{0, 0.5 * std::numbers::pi, {10.0, 20.0}};
  const Eigen::Vector2d q = place_point(pl, {3.0, 1.0});
  EXPECT_DOUBLE_EQ(q.x(), 10.0 - 1.0);
  EXPECT_DOUBLE_EQ(q.y(), 20.0 + 3.0);
}

// Usable 230 x 80: two 100 x 50 boxes per row (100 + 5 + 100 <= 230), one row (50 + 5 + 50 > 80).
TEST(NestMatrix, RowsAndSheetsCountedByHand) {
  std::vector<Part> parts;
  for (int i = 0; i < 4; ++i) parts.push_back(make_part(rect(100, 50, 300.0 * i, -40), 2.0, 1, i + 1));
  const Stock stock = one_sheet_kind(2.0, 250, 100);
  auto nest = nest_parts(parts, stock, matrix());
  ASSERT_TRUE(nest) << nest.error().message;
  check_nest(parts, stock, matrix(), *nest);
  ASSERT_EQ(nest->sheets.size(), 2u);
  EXPECT_EQ(nest->sheets[0].placements.size(), 2u);
  // First box at the margin corner, second one spacing to its right.
  const auto& p0 = nest->sheets[0].placements[0];
  const Polygon2 f0 = placed_footprint(parts[p0.part], p0);
  EXPECT_NEAR(f0[0].x(), 10.0, 1e-9);
  EXPECT_NEAR(f0[0].y(), 10.0, 1e-9);
  const auto& p1 = nest->sheets[0].placements[1];
  const Polygon2 f1 = placed_footprint(parts[p1.part], p1);
  EXPECT_NEAR(f1[0].x(), 115.0, 1e-9);
  EXPECT_NEAR(nest->sheets[0].utilisation, 2 * 5000.0 / 25000.0, 1e-12);
}

// A 60 x 150 part fits the 230 x 80 usable area only turned a quarter.
TEST(NestMatrix, TurnsAPartThatFitsOnlyTurned) {
  std::vector<Part> parts{make_part(rect(60, 150), 2.0, 1, 1)};
  const Stock stock = one_sheet_kind(2.0, 250, 100);
  auto nest = nest_parts(parts, stock, matrix());
  ASSERT_TRUE(nest) << nest.error().message;
  check_nest(parts, stock, matrix(), *nest);
  EXPECT_NEAR(nest->sheets.at(0).placements.at(0).rotation_rad, 0.5 * std::numbers::pi, 1e-15);
}

// Tall parts stand upright in a row made tall by an earlier part, instead of opening a new row.
TEST(NestMatrix, UprightInATallRow) {
  std::vector<Part> parts{make_part(rect(60, 60), 1.0, 1, 1), make_part(rect(50, 20), 1.0, 1, 2)};
  const Stock stock = one_sheet_kind(1.0, 200, 100);
  auto nest = nest_parts(parts, stock, matrix(2.0, 5.0));
  ASSERT_TRUE(nest) << nest.error().message;
  check_nest(parts, stock, matrix(2.0, 5.0), *nest);
  ASSERT_EQ(nest->sheets.size(), 1u);
  const auto& pl = nest->sheets[0].placements.at(1);
  EXPECT_EQ(pl.part, 1);
  EXPECT_NEAR(pl.rotation_rad, 0.5 * std::numbers::pi, 1e-15);
  const Polygon2 f = placed_footprint(parts[1], pl);
  double ymin = 1e9;
  for (const auto& p : f) ymin = std::min(ymin, p.y());
  EXPECT_NEAR(ymin, 5.0, 1e-9) << "same row as the first part";
}

}  // namespace
}  // namespace lamina
