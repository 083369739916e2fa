// True-shape nesting (libnest2d): invariants, the exact map back from libnest2d's transforms,
// shape versus matrix on L-shapes and triangles, determinism with and without threads.
#include "nest_checks.hpp"

// Private header of lamina_core: the packing step alone, with libnest2d's own placed shapes.
#include "cam/nest_internal.hpp"

#include <gtest/gtest.h>

#include <numbers>

namespace lamina {
namespace {

using namespace nest_test;

NestParams shape_params(NestMethod m, double spacing = 6.0, double margin = 10.0) {
  NestParams p;
  p.method = m;
  p.spacing_mm = spacing;
  p.margin_mm = margin;
  return p;
}

// libnest2d reports, per item, a rotation and a translation in nm and the shape it placed; the
// Placement we derive must map the item's raw shape onto that shape (to libnest2d's 1 nm
// truncation), for parts far from the origin too.
TEST(NestShape, PlacementReproducesLibnest2dTransform) {
  std::vector<Part> parts;
  std::vector<int> which;
  for (int i = 0; i < 12; ++i) {
    parts.push_back(make_part(i % 2 ? triangle(80, 50, 1000.0 + i, -700) : ell(90, 60, 25, -350, 420.5), 1.0, 1, i + 1));
    which.push_back(i);
  }
  std::vector<int> unplaced;
  cam_detail::ShapePackDiagnostics diag;
  const auto sheets = cam_detail::pack_shape(parts, which, {400, 300}, shape_params(NestMethod::shape), unplaced, &diag);
  EXPECT_TRUE(unplaced.empty());
  EXPECT_EQ(diag.items, 12);
  EXPECT_LT(diag.max_transform_error_mm, 2e-6);
  bool turned = false;
  for (const auto& s : sheets)
    for (const auto& pl : s.placements) turned |= std::abs(pl.rotation_rad) > 1e-9;
  EXPECT_TRUE(turned) << "a test of the rotation needs a turned part";
}

// Rectangles, L-shapes, discs and rings together: every invariant, for both methods.
TEST(NestShape, AllInvariantsOnMixedPartsForBothMethods) {
  std::vector<Part> parts;
  int island = 1;
  for (int i = 0; i < 6; ++i) parts.push_back(make_part(rect(120 + 10 * i, 40 + 7 * i, 50, 50), 1.0, 1, island++));
  for (int i = 0; i < 6; ++i) parts.push_back(make_part(ell(150, 90, 30, -20, 5), 1.0, 2, island++));
  for (int i = 0; i < 6; ++i) parts.push_back(make_part(circle(35 + 3 * i), 1.0, 3, island++));
  for (int i = 0; i < 4; ++i)
    parts.push_back(make_part(circle(60, 64, 400, 400), 1.0, 4, island++, std::numbers::pi * 30 * 30));
  const Stock stock = one_sheet_kind(1.0, 600, 400);
  for (NestMethod m : {NestMethod::matrix, NestMethod::shape}) {
    auto nest = nest_parts(parts, stock, shape_params(m));
    ASSERT_TRUE(nest) << nest.error().message;
    const Summary s = check_nest(parts, stock, shape_params(m), *nest);
    std::printf("[%s] %zu mixed parts on 600 x 400: %d sheets, mean utilisation %.3f\n", nest_method_name(m),
                parts.size(), s.sheets, s.mean_utilisation);
  }
}

// Parts that pair up turned (triangles) or whose boxes waste room (L-shapes): shape nesting needs
// no more sheets than matrix nesting.
TEST(NestShape, NoMoreSheetsThanMatrixOnTrianglesAndLShapes) {
  struct Case {
    const char* name;
    std::vector<Part> parts;
  };
  std::vector<Case> cases(2);
  cases[0].name = "triangles";
  cases[1].name = "L-shapes";
  for (int i = 0; i < 40; ++i) cases[0].parts.push_back(make_part(triangle(140, 90), 2.0, 1, i + 1));
  for (int i = 0; i < 30; ++i) cases[1].parts.push_back(make_part(ell(160, 120, 40), 2.0, 1, i + 1));
  const Stock stock = one_sheet_kind(2.0, 1000, 500);
  for (const Case& c : cases) {
    Summary got[2];
    for (NestMethod m : {NestMethod::matrix, NestMethod::shape}) {
      auto nest = nest_parts(c.parts, stock, shape_params(m));
      ASSERT_TRUE(nest) << nest.error().message;
      got[static_cast<int>(m)] = check_nest(c.parts, stock, shape_params(m), *nest);
      std::printf("[%s] %zu %s on 1000 x 500: %d sheets, mean utilisation %.3f\n", nest_method_name(m),
                  c.parts.size(), c.name, got[static_cast<int>(m)].sheets,
                  got[static_cast<int>(m)].mean_utilisation);
    }
    EXPECT_LE(got[1].sheets, got[0].sheets) << c.name;
  }
}

TEST(NestShape, SameResultWithAndWithoutThreads) {
  std::vector<Part> parts;
  for (int i = 0; i < 25; ++i)
    parts.push_back(make_part(i % 3 == 0 ? triangle(90, 60) : i % 3 == 1 ? ell(70, 80, 20) : circle(30), 1.0 + (i % 2),
                              1 + i % 2, i + 1));
  Stock stock;
  stock.sheets.push_back({1.0, 300, 500, 0, "", ""});
  stock.sheets.push_back({2.0, 300, 500, 0, "", ""});
  NestParams a = shape_params(NestMethod::shape);
  a.parallel = true;
  NestParams b = a;
  b.parallel = false;
  auto na = nest_parts(parts, stock, a);
  auto nb = nest_parts(parts, stock, b);
  ASSERT_TRUE(na && nb);
  ASSERT_EQ(na->sheets.size(), nb->sheets.size());
  for (std::size_t s = 0; s < na->sheets.size(); ++s) {
    ASSERT_EQ(na->sheets[s].placements.size(), nb->sheets[s].placements.size());
    for (std::size_t i = 0; i < na->sheets[s].placements.size(); ++i) {
      const auto& x = na->sheets[s].placements[i];
      const auto& y = nb->sheets[s].placements[i];
      EXPECT_EQ(x.part, y.part);
      EXPECT_EQ(x.rotation_rad, y.rotation_rad);
      EXPECT_EQ(x.offset_mm, y.offset_mm);
    }
  }
}

// Zero spacing and zero margin: parts may touch each other and the sheet edge, never overlap.
TEST(NestShape, ZeroSpacingAndMargin) {
  std::vector<Part> parts;
  for (int i = 0; i < 8; ++i) parts.push_back(make_part(rect(50, 50), 1.0, 1, i + 1));
  const Stock stock = one_sheet_kind(1.0, 200, 100);
  for (NestMethod m : {NestMethod::matrix, NestMethod::shape}) {
    auto nest = nest_parts(parts, stock, shape_params(m, 0.0, 0.0));
    ASSERT_TRUE(nest) << nest.error().message;
    check_nest(parts, stock, shape_params(m, 0.0, 0.0), *nest);
  }
}

}  // namespace
}  // namespace lamina
