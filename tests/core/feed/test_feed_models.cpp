// The two feed models against hand-computed examples (units written out) and their scaling laws.
#include "lamina/core/feed.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace lamina {
namespace {

// The jet of both hand examples: 380 MPa, 0.33 mm orifice, 1.02 mm focusing tube, C_d = 1.
JetSetup example_jet(double abrasive_kg_per_s) {
  JetSetup jet;
  jet.pressure_pa = 380e6;
  jet.orifice_diameter_m = 0.33e-3;
  jet.focus_diameter_m = 1.02e-3;
  jet.abrasive_rate_kg_per_s = abrasive_kg_per_s;
  jet.water_density_kg_per_m3 = 998.0;
  jet.discharge_coefficient = 1.0;
  return jet;
}

Material aluminium() {
  Material m;
  m.name = "aluminium 6061-T6";
  m.density_kg_per_m3 = 2700.0;
  m.specific_energy_j_per_m3 = 7.7e9;  // 7.7 J/mm³
  m.machinability = 213.0;
  return m;
}

// Limits wide enough that nothing in these tests is clamped.
FeedParams unclamped(FeedModel model, int quality = 3) {
  FeedParams p;
  p.model = model;
  p.quality = quality;
  p.min_feed_mm_per_s = 1e-9;
  p.max_feed_mm_per_s = 1e9;
  return p;
}

constexpr double kLbPerMinInKgPerS = 0.45359237 / 60.0;

TEST(FeedModels, WaterMassFlowByHand) {
  // v = √(2 · 380e6 Pa / 998 kg/m³) = √761 523 m²/s² = 872.65 m/s
  // A = π/4 · (0.33e-3 m)² = 8.5530e-8 m²
  // ṁ_w = 998 · 8.5530e-8 · 872.65 = 0.074489 kg/s (4.47 L/min)
  EXPECT_NEAR(water_mass_flow_kg_per_s(example_jet(0.0058)), 0.074489, 0.074489 * 1e-4);
  JetSetup half = example_jet(0.0058);
  half.discharge_coefficient = 0.5;
  EXPECT_NEAR(water_mass_flow_kg_per_s(half), 0.5 * 0.074489, 0.074489 * 1e-4);
}

TEST(FeedModels, ZengKimAluminium10mmByHand) {
  // Published units: P = 380 MPa / 6.894757 MPa/ksi = 55.1143 ksi; d_o = 0.33/25.4 = 0.012992 in;
  // d_m = 1.02/25.4 = 0.040157 in; M_a = 0.77 lb/min; h = 10/25.4 = 0.393701 in; N_m = 213; q = 3.
  //   P^1.594 = 596.45   d_o^1.374 = 0.0025597   M_a^0.343 = 0.91425   d_m^0.618 = 0.13713
  //   numerator   f_a N_m P^1.594 d_o^1.374 M_a^0.343 = 1 · 213 · 596.45 · 0.0025597 · 0.91425 = 297.32
  //   denominator C q h d_m^0.618 = 163 · 3 · 0.393701 · 0.13713 = 26.400
  //   u = (297.32 / 26.400)^1.15 = 11.262^1.15 = 16.194 in/min = 16.194 · 25.4 / 60 = 6.8555 mm/s
  const double by_hand_mm_per_s = 6.8555;
  const JetSetup jet = example_jet(0.77 * kLbPerMinInKgPerS);
  EXPECT_NEAR(zeng_kim_feed_mm_per_s(jet, aluminium(), 10.0, 3), by_hand_mm_per_s, by_hand_mm_per_s * 0.005);
  auto feed = cut_feed_mm_per_s(jet, aluminium(), unclamped(FeedModel::zeng_kim), 10.0, 0.0);
  ASSERT_TRUE(feed.has_value()) << feed.error().message;
  EXPECT_NEAR(*feed, by_hand_mm_per_s, by_hand_mm_per_s * 0.005);
}

TEST(FeedModels, LimbachiyaPatelAluminium10mmByHand) {
  // SI throughout. Water as in WaterMassFlowByHand: ṁ_w = 0.074489 kg/s, v = 872.65 m/s.
  //   R = 0.0058 / 0.074489 = 0.077864;   R/(1+R)² = 0.077864 / 1.16179 = 0.067021
  //   hydraulic power (π/4) d_o² p^{3/2} √(2/ρ_w) = 8.5530e-8 m² · 380e6 Pa · 872.65 m/s = 28 362 W
  //   abrasive share 28 362 W · 0.067021 = 1 900.9 W
  //   v_f = 1 900.9 W / (7.7e9 J/m³ · 1.02e-3 m · 10e-3 m) = 1 900.9 / 78 540 = 0.024203 m/s = 24.20 mm/s
  const double by_hand_mm_per_s = 24.20;
  const JetSetup jet = example_jet(0.0058);
  EXPECT_NEAR(limbachiya_patel_feed_mm_per_s(jet, aluminium(), 10.0), by_hand_mm_per_s, by_hand_mm_per_s * 0.005);
  auto feed = cut_feed_mm_per_s(jet, aluminium(), unclamped(FeedModel::limbachiya_patel), 10.0, 0.0);
  ASSERT_TRUE(feed.has_value()) << feed.error().message;
  EXPECT_NEAR(*feed, by_hand_mm_per_s, by_hand_mm_per_s * 0.005);
}

TEST(FeedModels, TiltLengthensThePath) {
  // h_f = t / cos(tilt): eq. 3 is ∝ 1/h_f, so feed ∝ cos(tilt); Zeng–Kim is ∝ h^-1.15, so ∝ cos^1.15.
  const JetSetup jet = example_jet(0.0058);
  for (FeedModel model : {FeedModel::limbachiya_patel, FeedModel::zeng_kim}) {
    const double exponent = model == FeedModel::limbachiya_patel ? 1.0 : 1.15;
    auto straight = cut_feed_mm_per_s(jet, aluminium(), unclamped(model), 8.0, 0.0);
    ASSERT_TRUE(straight.has_value());
    for (double tilt_deg : {10.0, -25.0, 45.0, 80.0}) {
      const double tilt = tilt_deg * std::numbers::pi / 180.0;
      auto tilted = cut_feed_mm_per_s(jet, aluminium(), unclamped(model), 8.0, tilt);
      ASSERT_TRUE(tilted.has_value());
      EXPECT_NEAR(*tilted / *straight, std::pow(std::cos(tilt), exponent), 1e-12)
          << feed_model_name(model) << " at " << tilt_deg << "°";
    }
  }
}

TEST(FeedModels, ThicknessScaling) {
  const JetSetup jet = example_jet(0.0058);
  EXPECT_NEAR(limbachiya_patel_feed_mm_per_s(jet, aluminium(), 20.0) / limbachiya_patel_feed_mm_per_s(jet, aluminium(), 5.0),
              0.25, 1e-12);
  EXPECT_NEAR(zeng_kim_feed_mm_per_s(jet, aluminium(), 20.0, 3) / zeng_kim_feed_mm_per_s(jet, aluminium(), 5.0, 3),
              std::pow(0.25, 1.15), 1e-12);
}

TEST(FeedModels, QualityScaling) {
  // u ∝ q^-1.15: a separation cut (q1) is 5^1.15 = 6.36 times faster than the finest (q5).
  const JetSetup jet = example_jet(0.0058);
  const double q1 = zeng_kim_feed_mm_per_s(jet, aluminium(), 12.0, 1);
  const double q5 = zeng_kim_feed_mm_per_s(jet, aluminium(), 12.0, 5);
  EXPECT_NEAR(q1 / q5, std::pow(5.0, 1.15), 1e-9);
  for (int q = 1; q < 5; ++q)
    EXPECT_GT(zeng_kim_feed_mm_per_s(jet, aluminium(), 12.0, q), zeng_kim_feed_mm_per_s(jet, aluminium(), 12.0, q + 1));
}

TEST(FeedModels, MaterialScaling) {
  // Zeng–Kim ∝ N_m^1.15; eq. 3 ∝ 1/μ_job.
  const JetSetup jet = example_jet(0.0058);
  Material steel = aluminium();
  steel.machinability = 81.0;
  steel.specific_energy_j_per_m3 = 23e9;
  EXPECT_NEAR(zeng_kim_feed_mm_per_s(jet, steel, 6.0, 2) / zeng_kim_feed_mm_per_s(jet, aluminium(), 6.0, 2),
              std::pow(81.0 / 213.0, 1.15), 1e-12);
  EXPECT_NEAR(limbachiya_patel_feed_mm_per_s(jet, steel, 6.0) / limbachiya_patel_feed_mm_per_s(jet, aluminium(), 6.0),
              7.7 / 23.0, 1e-12);
}

TEST(FeedModels, ModelNamesRoundTrip) {
  for (FeedModel m : {FeedModel::limbachiya_patel, FeedModel::zeng_kim}) {
    auto parsed = parse_feed_model(feed_model_name(m));
    ASSERT_TRUE(parsed.has_value());
    EXPECT_EQ(*parsed, m);
  }
  auto bad = parse_feed_model("hashish");
  ASSERT_FALSE(bad.has_value());
  EXPECT_EQ(bad.error().code, ErrorCode::invalid_argument);
  EXPECT_NE(bad.error().message.find("hashish"), std::string::npos);
  EXPECT_NE(bad.error().message.find("zeng_kim"), std::string::npos);
}

}  // namespace
}  // namespace lamina
