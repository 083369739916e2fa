// cut_feed_mm_per_s: clamping to the machine's feeds, and every input outside its domain named.
#include "lamina/core/feed.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

namespace lamina {
namespace {

Material steel() {
  Material m;
  m.name = "mild steel";
  m.density_kg_per_m3 = 7850.0;
  m.specific_energy_j_per_m3 = 23e9;
  m.machinability = 81.0;
  return m;
}

TEST(FeedLimits, ClampsToTheMachine) {
  const JetSetup jet;  // the header's defaults: 380 MPa, 0.33 / 1.02 mm, 5.8 g/s
  for (FeedModel model : {FeedModel::limbachiya_patel, FeedModel::zeng_kim}) {
    FeedParams p;
    p.model = model;
    p.min_feed_mm_per_s = 0.5;
    p.max_feed_mm_per_s = 20.0;
    const double raw_thick = model == FeedModel::zeng_kim ? zeng_kim_feed_mm_per_s(jet, steel(), 300.0, p.quality)
                                                          : limbachiya_patel_feed_mm_per_s(jet, steel(), 300.0);
    const double raw_thin = model == FeedModel::zeng_kim ? zeng_kim_feed_mm_per_s(jet, steel(), 0.2, p.quality)
                                                         : limbachiya_patel_feed_mm_per_s(jet, steel(), 0.2);
    const double raw_mid = model == FeedModel::zeng_kim ? zeng_kim_feed_mm_per_s(jet, steel(), 6.0, p.quality)
                                                        : limbachiya_patel_feed_mm_per_s(jet, steel(), 6.0);
    // The premise of each case, so the test fails if the models drift rather than pass vacuously.
    ASSERT_LT(raw_thick, p.min_feed_mm_per_s) << feed_model_name(model);
    ASSERT_GT(raw_thin, p.max_feed_mm_per_s) << feed_model_name(model);
    ASSERT_GT(raw_mid, p.min_feed_mm_per_s);
    ASSERT_LT(raw_mid, p.max_feed_mm_per_s);
    EXPECT_EQ(cut_feed_mm_per_s(jet, steel(), p, 300.0, 0.0).value(), 0.5);
    EXPECT_EQ(cut_feed_mm_per_s(jet, steel(), p, 0.2, 0.0).value(), 20.0);
    EXPECT_DOUBLE_EQ(cut_feed_mm_per_s(jet, steel(), p, 6.0, 0.0).value(), raw_mid);
  }
}

TEST(FeedLimits, EqualLimitsGiveThatFeed) {
  FeedParams p;
  p.min_feed_mm_per_s = 3.0;
  p.max_feed_mm_per_s = 3.0;
  EXPECT_EQ(cut_feed_mm_per_s(JetSetup{}, steel(), p, 6.0, 0.3).value(), 3.0);
}

struct BadInput {
  std::string name;  // must appear in the message
  std::function<void(JetSetup&, Material&, FeedParams&, double&, double&)> spoil;
};

TEST(FeedLimits, EveryInvalidInputIsNamed) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  const std::vector<BadInput> cases = {
      {"jet.pressure_pa", [](auto& j, auto&, auto&, auto&, auto&) { j.pressure_pa = 0.0; }},
      {"jet.pressure_pa", [&](auto& j, auto&, auto&, auto&, auto&) { j.pressure_pa = nan; }},
      {"jet.orifice_diameter_m", [](auto& j, auto&, auto&, auto&, auto&) { j.orifice_diameter_m = -0.33e-3; }},
      {"jet.focus_diameter_m", [](auto& j, auto&, auto&, auto&, auto&) { j.focus_diameter_m = 0.0; }},
      {"jet.abrasive_rate_kg_per_s", [](auto& j, auto&, auto&, auto&, auto&) { j.abrasive_rate_kg_per_s = 0.0; }},
      {"jet.water_density_kg_per_m3", [&](auto& j, auto&, auto&, auto&, auto&) { j.water_density_kg_per_m3 = inf; }},
      {"jet.discharge_coefficient", [](auto& j, auto&, auto&, auto&, auto&) { j.discharge_coefficient = 1.2; }},
      {"jet.discharge_coefficient", [](auto& j, auto&, auto&, auto&, auto&) { j.discharge_coefficient = 0.0; }},
      {"machinability", [](auto&, auto& m, auto& p, auto&, auto&) { p.model = FeedModel::zeng_kim; m.machinability = 0.0; }},
      {"specific_energy_j_per_m3",
       [](auto&, auto& m, auto& p, auto&, auto&) { p.model = FeedModel::limbachiya_patel; m.specific_energy_j_per_m3 = -1.0; }},
      {"quality", [](auto&, auto&, auto& p, auto&, auto&) { p.model = FeedModel::zeng_kim; p.quality = 0; }},
      {"quality", [](auto&, auto&, auto& p, auto&, auto&) { p.model = FeedModel::zeng_kim; p.quality = 6; }},
      {"thickness_mm", [](auto&, auto&, auto&, auto& t, auto&) { t = 0.0; }},
      {"thickness_mm", [&](auto&, auto&, auto&, auto& t, auto&) { t = nan; }},
      {"tilt_rad", [](auto&, auto&, auto&, auto&, auto& a) { a = std::numbers::pi / 2; }},
      {"tilt_rad", [](auto&, auto&, auto&, auto&, auto& a) { a = -2.0; }},
      {"tilt_rad", [&](auto&, auto&, auto&, auto&, auto& a) { a = nan; }},
      {"min_feed_mm_per_s", [](auto&, auto&, auto& p, auto&, auto&) { p.min_feed_mm_per_s = 0.0; }},
      {"max_feed_mm_per_s", [](auto&, auto&, auto& p, auto&, auto&) { p.max_feed_mm_per_s = p.min_feed_mm_per_s / 2; }},
  };
  for (const BadInput& c : cases) {
    JetSetup jet;
    Material material = steel();
    FeedParams params;
    double thickness_mm = 6.0;
    double tilt_rad = 0.2;
    ASSERT_TRUE(cut_feed_mm_per_s(jet, material, params, thickness_mm, tilt_rad).has_value());  // valid before spoiling
    c.spoil(jet, material, params, thickness_mm, tilt_rad);
    auto r = cut_feed_mm_per_s(jet, material, params, thickness_mm, tilt_rad);
    ASSERT_FALSE(r.has_value()) << c.name;
    EXPECT_EQ(r.error().code, ErrorCode::invalid_argument) << c.name;
    EXPECT_NE(r.error().message.find(c.name), std::string::npos) << "'" << c.name << "' not in: " << r.error().message;
  }
}

TEST(FeedLimits, OnlyTheChosenModelsInputsAreRequired) {
  // A material known by its machinability alone cuts with Zeng–Kim; one known by μ_job alone with eq. 3.
  Material only_nm = steel();
  only_nm.specific_energy_j_per_m3 = 0.0;
  Material only_mu = steel();
  only_mu.machinability = 0.0;
  FeedParams zk;
  zk.model = FeedModel::zeng_kim;
  FeedParams lp;
  lp.model = FeedModel::limbachiya_patel;
  lp.quality = 42;  // not read by eq. 3
  EXPECT_TRUE(cut_feed_mm_per_s(JetSetup{}, only_nm, zk, 6.0, 0.0).has_value());
  EXPECT_TRUE(cut_feed_mm_per_s(JetSetup{}, only_mu, lp, 6.0, 0.0).has_value());
  EXPECT_FALSE(cut_feed_mm_per_s(JetSetup{}, only_mu, zk, 6.0, 0.0).has_value());
  EXPECT_FALSE(cut_feed_mm_per_s(JetSetup{}, only_nm, lp, 6.0, 0.0).has_value());
}

}  // namespace
}  // namespace lamina
