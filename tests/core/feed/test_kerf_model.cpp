// The planner's kerf model (kerf.hpp, issue 20): its shape against the trends shops and the
// literature describe — taper grows with speed and reverses below the free ratio, trail-back
// grows as r^m and with the path — and the fit from test cuts recovering known coefficients from
// noisy synthetic measurements, with the residuals a person reads.
#include "lamina/core/kerf.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace lamina {
namespace {

const KerfModel kModel{.top_width_mm = 0.95,
                       .top_width_per_ratio_mm = -0.08,
                       .taper_per_ratio = 0.05,
                       .taper_free_ratio = 0.25,
                       .trail_back_factor = 0.15,
                       .trail_back_exponent = 1.8};

KerfShape at(double path_mm, double ratio) {
  auto k = kerf_at(kModel, path_mm, ratio);
  EXPECT_TRUE(k) << k.error().message;
  return k.value_or(KerfShape{});
}

TEST(KerfModel, TaperGrowsWithSpeedAndReversesWhenSlowEnough) {
  double previous = -1e9;
  for (double r : {0.3, 0.5, 0.75, 1.0}) {
    const KerfShape k = at(10.0, r);
    const double taper = k.top_width_mm - k.bottom_width_mm;
    EXPECT_GT(taper, 0.0) << "V-shaped at r " << r;
    EXPECT_GT(taper, previous) << "wider taper at r " << r;
    EXPECT_GT(k.wall_lean_rad, 0.0);
    previous = taper;
  }
  const KerfShape slow = at(10.0, 0.1);
  EXPECT_LT(slow.top_width_mm, slow.bottom_width_mm) << "reversed below r0 = 0.25";
  EXPECT_LT(slow.wall_lean_rad, 0.0);
  const KerfShape free = at(10.0, 0.25);
  EXPECT_NEAR(free.top_width_mm, free.bottom_width_mm, 1e-12);
  // Twice the path, twice the width difference: the lean is a property of the speed.
  EXPECT_NEAR(at(20.0, 0.8).wall_lean_rad, at(10.0, 0.8).wall_lean_rad, 1e-3);
}

TEST(KerfModel, TrailBackGrowsAsThePowerOfTheSpeedAndWithThePath) {
  EXPECT_NEAR(at(10.0, 0.8).trail_back_mm / at(10.0, 0.4).trail_back_mm, std::pow(2.0, 1.8), 1e-9);
  EXPECT_NEAR(at(20.0, 0.6).trail_back_mm / at(10.0, 0.6).trail_back_mm, 2.0, 1e-9);
  EXPECT_NEAR(at(10.0, 1.0).trail_back_mm, 1.5, 1e-12) << "c · h_f at the separation speed";
}

TEST(KerfModel, OutsideWhatItDescribesIsAnError) {
  EXPECT_FALSE(kerf_at(kModel, 0.0, 0.5));
  EXPECT_FALSE(kerf_at(kModel, 10.0, -0.1));
  EXPECT_FALSE(kerf_at(kModel, 10.0, std::nan("")));
  // 200 mm at three times the separation speed: the bottom width would be negative.
  auto beyond = kerf_at(kModel, 200.0, 3.0);
  ASSERT_FALSE(beyond);
  EXPECT_NE(beyond.error().message.find("beyond what it was calibrated for"), std::string::npos) << beyond.error().message;
}

// A coupon as `lamina calibrate coupon` cuts it: three paths, five speeds, each measured by a
// person with a caliper (±0.01 mm on widths) and a trail-back gauge (±3 %).
std::vector<KerfMeasurement> coupon(const KerfModel& truth, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> caliper(0.0, 0.01), gauge(0.0, 0.03);
  std::vector<KerfMeasurement> cuts;
  for (double path : {5.0, 10.0, 20.0})
    for (double r : {0.15, 0.3, 0.5, 0.75, 1.0}) {
      const KerfShape k = *kerf_at(truth, path, r);
      cuts.push_back({"h" + std::to_string(static_cast<int>(path)) + "-r" + std::to_string(r).substr(0, 4), path, r,
                      k.top_width_mm + caliper(rng), k.bottom_width_mm + caliper(rng), k.trail_back_mm * (1.0 + gauge(rng))});
    }
  return cuts;
}

TEST(KerfFit, RecoversKnownCoefficientsFromNoisyCuts) {
  for (unsigned seed : {1u, 2u, 3u}) {
    const auto cuts = coupon(kModel, seed);
    auto fit = fit_kerf_model(cuts);
    ASSERT_TRUE(fit) << fit.error().message;
    const KerfModel& m = fit->model;
    EXPECT_NEAR(m.top_width_mm, 0.95, 0.02) << seed;
    EXPECT_NEAR(m.top_width_per_ratio_mm, -0.08, 0.03) << seed;
    EXPECT_NEAR(m.taper_per_ratio, 0.05, 0.005) << seed;
    EXPECT_NEAR(m.taper_free_ratio, 0.25, 0.05) << seed;
    EXPECT_NEAR(m.trail_back_factor, 0.15, 0.015) << seed;
    EXPECT_NEAR(m.trail_back_exponent, 1.8, 0.08) << seed;
    ASSERT_EQ(fit->residuals.size(), cuts.size());
    EXPECT_EQ(fit->residuals.front().label, cuts.front().label);
    // The residuals are the measurement noise, not a misfit.
    EXPECT_LT(fit->rms_width_mm, 0.02) << seed;
    EXPECT_GT(fit->rms_width_mm, 0.003) << seed;
    EXPECT_LT(fit->rms_trail_back_mm, 0.05) << seed;
  }
}

TEST(KerfFit, ExactCutsGiveTheExactModel) {
  KerfModel truth = kModel;
  truth.taper_free_ratio = 0.05;  // a hard material: V-shaped at every speed cut
  std::vector<KerfMeasurement> cuts;
  for (double r : {0.2, 0.6, 0.9}) {
    const KerfShape k = *kerf_at(truth, 8.0, r);
    cuts.push_back({"", 8.0, r, k.top_width_mm, k.bottom_width_mm, k.trail_back_mm});
  }
  auto fit = fit_kerf_model(cuts);
  ASSERT_TRUE(fit) << fit.error().message;
  EXPECT_NEAR(fit->model.taper_free_ratio, 0.05, 1e-9);
  EXPECT_NEAR(fit->model.trail_back_exponent, 1.8, 1e-9);
  EXPECT_NEAR(fit->model.top_width_per_ratio_mm, -0.08, 1e-9);
  EXPECT_LT(fit->rms_width_mm, 1e-9);
}

// The fastest cuts on the longest path did not go through (the machine's separation speed is
// below the feed model's): read as a bottom width of 0 and no trail-back, they still give their
// top width, and the rest of the coupon gives the taper and the trail-back.
TEST(KerfFit, ACutThatDidNotGoThroughFitsItsTopOnly) {
  auto cuts = coupon(kModel, 4);
  int dropped = 0;
  for (KerfMeasurement& c : cuts)
    if (c.path_mm == 20.0 && c.feed_ratio >= 0.75) c.bottom_width_mm = 0.0, c.trail_back_mm = 0.0, ++dropped;
  ASSERT_EQ(dropped, 2);
  auto fit = fit_kerf_model(cuts);
  ASSERT_TRUE(fit) << fit.error().message;
  EXPECT_NEAR(fit->model.taper_per_ratio, 0.05, 0.006);
  EXPECT_NEAR(fit->model.trail_back_exponent, 1.8, 0.1);
  EXPECT_NEAR(fit->model.top_width_mm, 0.95, 0.02);
  int not_through = 0;
  for (const KerfResidual& r : fit->residuals) {
    not_through += !r.through;
    if (!r.through) EXPECT_EQ(r.bottom_width_mm, 0.0) << "not measured, not a residual";
  }
  EXPECT_EQ(not_through, 2);
  EXPECT_LT(fit->rms_width_mm, 0.02) << "the missing bottoms do not count as misfits";
}

TEST(KerfFit, MeasurementsThatCannotFitAreRefusedByName) {
  std::vector<KerfMeasurement> one_speed{{"a", 10, 0.5, 0.95, 0.9, 0.4}, {"b", 5, 0.5, 0.95, 0.92, 0.2}};
  auto r = fit_kerf_model(one_speed);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("two speeds"), std::string::npos) << r.error().message;

  std::vector<KerfMeasurement> missing{{"a", 10, 0.5, 0.95, 0.9, 0.4}, {"arc-3", 10, 0.9, 0.93, 0.85, 0.0}};
  r = fit_kerf_model(missing);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("cut 'arc-3': trail-back 0 mm"), std::string::npos) << r.error().message;

  std::vector<KerfMeasurement> unnamed{{"", 10, 0.5, 0.95, -0.9, 0.4}};
  r = fit_kerf_model(unnamed);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("row 1: widths"), std::string::npos) << r.error().message;
}

}  // namespace
}  // namespace lamina
