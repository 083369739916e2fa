// The driver: thickness groups thin first, stock entries in rack order up to their counts,
// sheet numbering, and the inventory errors (each names the thickness).
#include "nest_checks.hpp"

#include <gtest/gtest.h>

namespace lamina {
namespace {

using namespace nest_test;

NestParams params_for(NestMethod m) {
  NestParams p;
  p.method = m;
  p.spacing_mm = 4.0;
  p.margin_mm = 8.0;
  return p;
}

class NestDriver : public ::testing::TestWithParam<NestMethod> {};

TEST_P(NestDriver, ThinSheetsFirstWhateverThePartOrder) {
  std::vector<Part> parts;
  // Thick parts first in the input, and the thick sheet first in the rack.
  for (int i = 0; i < 3; ++i) parts.push_back(make_part(rect(150, 150), 5.0, 2, i + 1));
  for (int i = 0; i < 3; ++i) parts.push_back(make_part(rect(150, 150), 1.0, 1, i + 1));
  for (int i = 0; i < 3; ++i) parts.push_back(make_part(rect(150, 150), 2.5, 3, i + 1));
  Stock stock;
  stock.sheets.push_back({5.0, 200, 200, 0, "al", ""});
  stock.sheets.push_back({2.5, 200, 200, 0, "al", ""});
  stock.sheets.push_back({1.0, 200, 200, 0, "al", ""});
  const NestParams params = params_for(GetParam());
  auto nest = nest_parts(parts, stock, params);
  ASSERT_TRUE(nest) << nest.error().message;
  check_nest(parts, stock, params, *nest);
  ASSERT_EQ(nest->sheets.size(), 9u);  // one 150 x 150 part per 184 x 184 usable sheet
  for (int i = 0; i < 9; ++i) EXPECT_EQ(nest->sheets[i].thickness_mm, (i < 3 ? 1.0 : i < 6 ? 2.5 : 5.0));
}

TEST_P(NestDriver, StockEntriesInRackOrderUpToTheirCounts) {
  std::vector<Part> parts;
  for (int i = 0; i < 7; ++i) parts.push_back(make_part(rect(150, 150), 5.0, 1, i + 1));
  Stock stock;
  stock.sheets.push_back({5.0, 200, 200, 2, "big", ""});
  stock.sheets.push_back({1.0, 200, 200, 9, "thin", ""});
  stock.sheets.push_back({5.0, 180, 180, 0, "offcut", ""});
  const NestParams params = params_for(GetParam());
  auto nest = nest_parts(parts, stock, params);
  ASSERT_TRUE(nest) << nest.error().message;
  check_nest(parts, stock, params, *nest);
  ASSERT_EQ(nest->sheets.size(), 7u);
  EXPECT_EQ(nest->sheets[0].stock_index, 0);
  EXPECT_EQ(nest->sheets[1].stock_index, 0);
  for (int i = 2; i < 7; ++i) EXPECT_EQ(nest->sheets[i].stock_index, 2);
  EXPECT_EQ(nest->sheets[2].material, "offcut");
}

TEST_P(NestDriver, PartsTooBigForTheFirstEntryGoToALaterOne) {
  std::vector<Part> parts{make_part(rect(50, 50), 3.0, 1, 1), make_part(rect(300, 100), 3.0, 1, 2)};
  Stock stock;
  stock.sheets.push_back({3.0, 100, 100, 5, "small", ""});
  stock.sheets.push_back({3.0, 200, 400, 5, "long", ""});
  const NestParams params = params_for(GetParam());
  auto nest = nest_parts(parts, stock, params);
  ASSERT_TRUE(nest) << nest.error().message;
  check_nest(parts, stock, params, *nest);
  ASSERT_EQ(nest->sheets.size(), 2u);
  EXPECT_EQ(nest->sheets[0].stock_index, 0);
  EXPECT_EQ(nest->sheets[0].placements.at(0).part, 0);
  EXPECT_EQ(nest->sheets[1].stock_index, 1);
  EXPECT_EQ(nest->sheets[1].placements.at(0).part, 1);
}

TEST_P(NestDriver, NoSheetOfThatThickness) {
  std::vector<Part> parts{make_part(rect(10, 10), 1.0, 1, 1), make_part(rect(10, 10), 2.5, 4, 1)};
  const Stock stock = one_sheet_kind(1.0, 100, 100);
  auto nest = nest_parts(parts, stock, params_for(GetParam()));
  ASSERT_FALSE(nest);
  EXPECT_EQ(nest.error().code, ErrorCode::invalid_argument);
  EXPECT_NE(nest.error().message.find("no sheet of thickness 2.5 mm"), std::string::npos) << nest.error().message;
  EXPECT_NE(nest.error().message.find("L4-1"), std::string::npos) << nest.error().message;
}

TEST_P(NestDriver, SheetSizeUnknown) {
  std::vector<Part> parts{make_part(rect(10, 10), 2.0, 1, 1)};
  const Stock stock = one_sheet_kind(2.0, 0, 1000);
  auto nest = nest_parts(parts, stock, params_for(GetParam()));
  ASSERT_FALSE(nest);
  EXPECT_EQ(nest.error().code, ErrorCode::invalid_argument);
  EXPECT_NE(nest.error().message.find("2 mm sheet"), std::string::npos) << nest.error().message;
  EXPECT_NE(nest.error().message.find("no known size"), std::string::npos) << nest.error().message;
}

TEST_P(NestDriver, PartBiggerThanEverySheet) {
  std::vector<Part> parts{make_part(rect(10, 10), 2.0, 3, 1), make_part(rect(500, 120), 2.0, 3, 2)};
  Stock stock;
  stock.sheets.push_back({2.0, 200, 400, 0, "", ""});  // usable 380 x 180 (margin 10)
  stock.sheets.push_back({2.0, 100, 450, 0, "", ""});  // usable 430 x 80
  NestParams params = params_for(GetParam());
  params.margin_mm = 10.0;
  auto nest = nest_parts(parts, stock, params);
  ASSERT_FALSE(nest);
  EXPECT_EQ(nest.error().code, ErrorCode::invalid_argument);
  const std::string& m = nest.error().message;
  EXPECT_NE(m.find("L3-2"), std::string::npos) << m;
  EXPECT_NE(m.find("500.0 x 120.0 mm"), std::string::npos) << m;
  EXPECT_NE(m.find("every 2 mm sheet"), std::string::npos) << m;
}

TEST_P(NestDriver, NotEnoughSheets) {
  std::vector<Part> parts;
  for (int i = 0; i < 5; ++i) parts.push_back(make_part(rect(150, 150), 10.0, 7, i + 1));
  Stock stock;
  stock.sheets.push_back({10.0, 200, 200, 1, "", ""});
  stock.sheets.push_back({10.0, 190, 190, 2, "", ""});
  auto nest = nest_parts(parts, stock, params_for(GetParam()));
  ASSERT_FALSE(nest);
  EXPECT_EQ(nest.error().code, ErrorCode::stock_exhausted);
  const std::string& m = nest.error().message;
  EXPECT_NE(m.find("not enough 10 mm sheets: 3 in stock"), std::string::npos) << m;
  EXPECT_NE(m.find("at least 5 sheets needed (2 more of 190 x 190 mm)"), std::string::npos) << m;
}

// The planner lays the stack out again with what the rack held (issue 17, item 5): each
// thickness that ran out says how many of its layers were placed whole.
TEST_P(NestDriver, ShortagesCountTheLayersPlacedWhole) {
  std::vector<Part> parts;
  for (int layer = 0; layer < 5; ++layer) {
    parts.push_back(make_part(rect(150, 150), 10.0, layer, 1));
    parts.back().layer_slot = layer;
  }
  parts.push_back(make_part(rect(20, 20), 1.0, 9, 1));  // a thickness with enough sheets
  parts.back().layer_slot = 9;
  Stock stock;
  stock.sheets.push_back({10.0, 200, 200, 3, "", ""});
  stock.sheets.push_back({1.0, 100, 100, 1, "", ""});
  std::vector<SheetShortage> shortages;
  auto nest = nest_parts(parts, stock, params_for(GetParam()), &shortages);
  ASSERT_FALSE(nest);
  EXPECT_EQ(nest.error().code, ErrorCode::stock_exhausted);
  ASSERT_EQ(shortages.size(), 1u);
  EXPECT_EQ(shortages[0].thickness_mm, 10.0);
  EXPECT_EQ(shortages[0].layers, 5);
  EXPECT_EQ(shortages[0].layers_placed, 3) << "one 150 mm part per 200 mm sheet, three sheets";
}

TEST_P(NestDriver, BadParameters) {
  std::vector<Part> parts{make_part(rect(10, 10), 1.0, 1, 1)};
  const Stock stock = one_sheet_kind(1.0, 100, 100);
  NestParams p = params_for(GetParam());
  p.spacing_mm = -1;
  EXPECT_FALSE(nest_parts(parts, stock, p));
  p = params_for(GetParam());
  p.margin_mm = std::nan("");
  EXPECT_FALSE(nest_parts(parts, stock, p));
  std::vector<Part> cw{make_part(rect(10, 10), 1.0, 1, 1)};
  std::reverse(cw[0].footprint_mm.begin(), cw[0].footprint_mm.end());
  EXPECT_FALSE(nest_parts(cw, stock, params_for(GetParam())));
}

TEST_P(NestDriver, NoPartsNoSheets) {
  auto nest = nest_parts({}, Stock{}, params_for(GetParam()));
  ASSERT_TRUE(nest);
  EXPECT_TRUE(nest->sheets.empty());
}

INSTANTIATE_TEST_SUITE_P(BothMethods, NestDriver, ::testing::Values(NestMethod::matrix, NestMethod::shape),
                         [](const auto& info) { return std::string(nest_method_name(info.param)); });

}  // namespace
}  // namespace lamina
