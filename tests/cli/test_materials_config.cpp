// config/materials.toml and its loader (daemon/cli/materials_config.cpp): units converted at the edge,
// every mistake named with file:line, the shipped file consistent with config/stock.toml.
#include "materials_config.hpp"
#include "stock_config.hpp"

#include <gtest/gtest.h>

#include <string>

namespace lamina::cli {
namespace {

const std::string kConfigDir = LAMINA_CONFIG_DIR;

TEST(MaterialsConfig, ConvertsUnitsOnce) {
  auto c = parse_materials_toml(R"(
[jet]
pressure_mpa = 400
orifice_diameter_mm = 0.25
focus_diameter_mm = 0.76
abrasive_g_per_min = 300
discharge_coefficient = 0.8

[[material]]
name = "x"
density_kg_per_m3 = 2700
specific_energy_j_per_mm3 = 7.5
machinability = 200
)",
                                "t.toml");
  ASSERT_TRUE(c.has_value()) << c.error().message;
  EXPECT_DOUBLE_EQ(c->jet.pressure_pa, 400e6);
  EXPECT_DOUBLE_EQ(c->jet.orifice_diameter_m, 0.25e-3);
  EXPECT_DOUBLE_EQ(c->jet.focus_diameter_m, 0.76e-3);
  EXPECT_DOUBLE_EQ(c->jet.abrasive_rate_kg_per_s, 0.3 / 60.0);  // 300 g/min = 5 g/s
  EXPECT_DOUBLE_EQ(c->jet.discharge_coefficient, 0.8);
  EXPECT_DOUBLE_EQ(c->jet.water_density_kg_per_m3, JetSetup{}.water_density_kg_per_m3);  // absent: default
  auto m = find_material(*c, "x");
  ASSERT_TRUE(m.has_value());
  EXPECT_DOUBLE_EQ(m->specific_energy_j_per_m3, 7.5e9);  // J/mm³ → J/m³
  EXPECT_DOUBLE_EQ(m->machinability, 200.0);
  EXPECT_DOUBLE_EQ(m->density_kg_per_m3, 2700.0);
}

TEST(MaterialsConfig, MistakesAreNamedWithTheirLine) {
  struct Case {
    const char* text;
    const char* expect;  // in the message, after "t.toml:LINE:"
    int line;
  };
  const Case cases[] = {
      {"[[material]]\nname = \"a\"\nmachinabilty = 3\n", "unknown key 'machinabilty'", 3},
      {"[[material]]\nname = \"a\"\nmachinability = -3\n", "machinability = -3 is out of range", 3},
      {"[jet]\npressure_psi = 55000\n[[material]]\nname = \"a\"\nmachinability = 3\n", "unknown key 'pressure_psi'", 2},
      {"[jet]\ndischarge_coefficient = 1.5\n[[material]]\nname = \"a\"\nmachinability = 3\n", "discharge_coefficient = 1.5", 2},
      {"[jet]\npressure_mpa = \"380\"\n[[material]]\nname = \"a\"\nmachinability = 3\n", "pressure_mpa must be a number", 2},
      {"[[material]]\nname = \"a\"\nmachinability = 3\n[[material]]\nname = \"a\"\nmachinability = 4\n", "given twice", 4},
      {"[[material]]\nname = \"a\"\ndensity_kg_per_m3 = 2700\n", "neither specific_energy_j_per_mm3 nor machinability", 1},
      {"colour = 3\n[[material]]\nname = \"a\"\nmachinability = 3\n", "unknown key 'colour'", 1},
  };
  for (const Case& c : cases) {
    auto r = parse_materials_toml(c.text, "t.toml");
    ASSERT_FALSE(r.has_value()) << c.text;
    EXPECT_EQ(r.error().code, ErrorCode::parse_error);
    EXPECT_NE(r.error().message.find(c.expect), std::string::npos) << r.error().message;
    EXPECT_EQ(r.error().message.rfind("t.toml:" + std::to_string(c.line) + ":", 0), 0u) << r.error().message;
  }
}

TEST(MaterialsConfig, UnknownMaterialListsTheKnownOnes) {
  auto c = parse_materials_toml("[[material]]\nname = \"b\"\nmachinability = 1\n[[material]]\nname = \"a\"\nmachinability = 2\n",
                                "t.toml");
  ASSERT_TRUE(c.has_value());
  auto m = find_material(*c, "aluminum");
  ASSERT_FALSE(m.has_value());
  EXPECT_EQ(m.error().code, ErrorCode::invalid_argument);
  EXPECT_NE(m.error().message.find("'aluminum'"), std::string::npos) << m.error().message;
  EXPECT_NE(m.error().message.find("'a', 'b'"), std::string::npos) << m.error().message;
}

TEST(MaterialsConfig, ShippedFileCoversTheStockAndGivesFeeds) {
  auto c = load_materials(kConfigDir + "/materials.toml");
  ASSERT_TRUE(c.has_value()) << c.error().message;
  auto stock = read_stock_file(kConfigDir + "/stock.toml");
  ASSERT_TRUE(stock.has_value()) << stock.error().message;
  for (const SheetStock& s : stock->sheets) {
    if (s.material.empty()) continue;
    auto m = find_material(*c, s.material);
    ASSERT_TRUE(m.has_value()) << m.error().message;
    for (FeedModel model : {FeedModel::limbachiya_patel, FeedModel::zeng_kim}) {
      FeedParams p;
      p.model = model;
      auto f = cut_feed_mm_per_s(c->jet, *m, p, s.thickness_mm, 0.0);
      ASSERT_TRUE(f.has_value()) << f.error().message;
      EXPECT_GT(*f, p.min_feed_mm_per_s) << s.material << " " << s.thickness_mm << " mm";
    }
  }
  // Easier materials cut faster (both models): aluminium above titanium above stainless.
  FeedParams p;
  const auto feed = [&](const char* name) { return cut_feed_mm_per_s(c->jet, find_material(*c, name).value(), p, 10.0, 0.0).value(); };
  EXPECT_GT(feed("aluminium 6061-T6"), feed("titanium Ti-6Al-4V"));
  EXPECT_GT(feed("titanium Ti-6Al-4V"), feed("stainless 304"));
}

TEST(MaterialsConfig, MissingFileIsAnIoError) {
  auto c = load_materials(kConfigDir + "/no-such-file.toml");
  ASSERT_FALSE(c.has_value());
  EXPECT_EQ(c.error().code, ErrorCode::io_error);
}

}  // namespace
}  // namespace lamina::cli
