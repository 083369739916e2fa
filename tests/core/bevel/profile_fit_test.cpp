// fit_profile on analytic profiles: classes, the outside/inside rules, the tilt limit and the
// deviation it reports (bevel_profile.hpp has the conventions: material at u < surface).
#include "lamina/core/bevel_profile.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <numbers>

namespace lamina {
namespace {

using Curve = std::function<double(double)>;

// Samples every `step` from zb to zt of u(z), with the exact tangent slope.
std::vector<ProfileSample> sample(const Curve& u, double zb, double zt, double step) {
  std::vector<ProfileSample> s;
  const int n = static_cast<int>(std::round((zt - zb) / step));
  for (int i = 0; i <= n; ++i) {
    const double z = zb + (zt - zb) * i / n;
    const double h = 1e-6;
    s.push_back({z, u(z), (u(z + h) - u(z - h)) / (2 * h), true});
  }
  return s;
}

// Largest amount by which the cut edge goes behind (negative) or beyond (positive) the surface
// on a fine grid: the continuous check, not just at the samples.
std::pair<double, double> edge_vs_surface(const ProfileFit& fit, const Curve& u, double zb, double zt) {
  double most_inside = 0, most_outside = 0;
  for (int i = 0; i <= 1000; ++i) {
    const double z = zb + (zt - zb) * i / 1000.0;
    const double d = cut_edge_at(fit, z, zb, zt) - u(z);
    most_inside = std::min(most_inside, d);
    most_outside = std::max(most_outside, d);
  }
  return {most_inside, most_outside};
}

// Equator band of a sphere R 50: the surface falls back as z rises (convex).
const Curve kConvex = [](double z) { return std::sqrt(2500.0 - z * z) - 50.0; };
// A fillet-like hollow: the surface bends in towards the material (concave).
const Curve kConcave = [](double z) { return 20.0 - std::sqrt(400.0 - (z - 5.0) * (z - 5.0)); };

TEST(ProfileFit, ConvexCurvedOutsideGivesOneTangentPerSubSliceAndNeverCutsIn) {
  const auto s = sample(kConvex, 0, 10, 0.5);
  ProfileFitParams p;
  const auto fit = fit_profile(s, 0, 10, p);
  EXPECT_EQ(fit.shape, ProfileShape::convex);
  EXPECT_TRUE(fit.slope_rule_agrees);
  EXPECT_EQ(fit.cuts.size(), s.size());
  EXPECT_FALSE(fit.tilt_limited);
  const auto [in, out] = edge_vs_surface(fit, kConvex, 0, 10);
  EXPECT_GE(in, -1e-9) << "a cut removes part material";
  EXPECT_LT(out, 0.01);
  EXPECT_LT(fit.max_deviation_mm, 0.01);
  EXPECT_GE(fit.max_deviation_mm, out * 0.5);
}

TEST(ProfileFit, StrategiesOrderedOnAConvexProfile) {
  const auto s = sample(kConvex, 0, 10, 0.5);
  ProfileFitParams p;
  p.strategy = BevelStrategy::curved;
  const double curved = fit_profile(s, 0, 10, p).max_deviation_mm;
  p.strategy = BevelStrategy::sloped;
  const auto sloped_fit = fit_profile(s, 0, 10, p);
  p.strategy = BevelStrategy::vertical;
  const auto vertical_fit = fit_profile(s, 0, 10, p);
  EXPECT_EQ(sloped_fit.cuts.size(), 1u);
  EXPECT_EQ(vertical_fit.cuts.size(), 1u);
  EXPECT_GE(edge_vs_surface(sloped_fit, kConvex, 0, 10).first, -1e-9);
  EXPECT_GE(edge_vs_surface(vertical_fit, kConvex, 0, 10).first, -1e-9);
  EXPECT_LT(curved, sloped_fit.max_deviation_mm);
  EXPECT_LT(sloped_fit.max_deviation_mm, vertical_fit.max_deviation_mm);
  // Vertical edge at the widest point (z = 0); the surface at z = 10 is 1.0102 mm behind it,
  // and the closest surface point to the edge's top corner is a little nearer than that.
  EXPECT_NEAR(vertical_fit.cuts[0].u_top_mm, 0.0, 1e-12);
  EXPECT_NEAR(vertical_fit.max_deviation_mm, 50.0 - std::sqrt(2500.0 - 100.0), 0.02);
}

TEST(ProfileFit, ConcaveGetsOneChordOutsideTheSurface) {
  const auto s = sample(kConcave, 0, 10, 0.5);
  ProfileFitParams p;
  const auto fit = fit_profile(s, 0, 10, p);
  EXPECT_EQ(fit.shape, ProfileShape::concave);
  EXPECT_TRUE(fit.slope_rule_agrees);
  ASSERT_EQ(fit.cuts.size(), 1u);
  EXPECT_NEAR(fit.cuts[0].u_bottom_mm, kConcave(0), 1e-9);
  EXPECT_NEAR(fit.cuts[0].u_top_mm, kConcave(10), 1e-9);
  const auto [in, out] = edge_vs_surface(fit, kConcave, 0, 10);
  EXPECT_GE(in, -1e-9);
  const double sagitta = 20.0 - std::sqrt(400.0 - 25.0);
  EXPECT_NEAR(out, sagitta, 1e-3);
  EXPECT_NEAR(fit.max_deviation_mm, sagitta, 0.02);
}

TEST(ProfileFit, StraightAndMixed) {
  const Curve line = [](double z) { return 0.3 * z - 1.0; };
  ProfileFitParams p;
  const auto s = sample(line, 0, 5, 0.5);
  const auto fit = fit_profile(s, 0, 5, p);
  EXPECT_EQ(fit.shape, ProfileShape::straight);
  ASSERT_EQ(fit.cuts.size(), 1u);
  EXPECT_NEAR(fit.cuts[0].u_bottom_mm, -1.0, 1e-9);
  EXPECT_NEAR(fit.cuts[0].u_top_mm, 0.5, 1e-9);
  EXPECT_LT(fit.max_deviation_mm, 1e-9);

  const Curve wave = [](double z) { return 0.5 * std::sin(z); };
  const auto sw = sample(wave, 0, 2 * M_PI, 0.25);
  const auto mixed = fit_profile(sw, 0, 2 * M_PI, p);
  EXPECT_EQ(mixed.shape, ProfileShape::mixed);
  ASSERT_EQ(mixed.cuts.size(), 1u);
  EXPECT_GE(edge_vs_surface(mixed, wave, 0, 2 * M_PI).first, -2e-3);  // supports the samples
}

TEST(ProfileFit, TiltLimitHoldsTheLineAtTheLimitStillOutside) {
  const Curve steep = [](double z) { return -2.0 * z; };  // 63.4° from vertical
  ProfileFitParams p;
  p.tilt_max_rad = 60.0 * M_PI / 180.0;
  const auto s = sample(steep, 0, 2, 0.5);
  const auto fit = fit_profile(s, 0, 2, p);
  EXPECT_TRUE(fit.tilt_limited);
  ASSERT_EQ(fit.cuts.size(), 1u);
  const double slope = (fit.cuts[0].u_top_mm - fit.cuts[0].u_bottom_mm) / 2.0;
  EXPECT_NEAR(slope, -std::tan(p.tilt_max_rad), 1e-9);
  EXPECT_GE(edge_vs_surface(fit, steep, 0, 2).first, -1e-9);
  EXPECT_GT(fit.max_deviation_mm, 0.1);
  p.tilt_max_rad = 70.0 * M_PI / 180.0;
  EXPECT_FALSE(fit_profile(s, 0, 2, p).tilt_limited);
}

TEST(ProfileFit, InsideNeverLeavesMaterialBeyondTheSurface) {
  ProfileFitParams p;
  p.side = CutSide::inside;
  for (const Curve* c : {&kConvex, &kConcave}) {
    const auto s = sample(*c, 0, 10, 0.5);
    const auto fit = fit_profile(s, 0, 10, p);
    // At the samples the edge is never beyond the surface (between samples the polyline of a
    // convex surface is inside by construction).
    for (const auto& smp : s) EXPECT_LE(cut_edge_at(fit, smp.z_mm, 0, 10), smp.u_mm + 1e-9);
    EXPECT_LE(edge_vs_surface(fit, *c, 0, 10).second, 1e-9);
  }
}

TEST(ProfileFit, MixedSideStraddlesTheSurface) {
  ProfileFitParams p;
  p.side = CutSide::mixed;
  p.strategy = BevelStrategy::sloped;
  const auto s = sample(kConcave, 0, 10, 0.5);
  const auto fit = fit_profile(s, 0, 10, p);
  double lo = 1e9, hi = -1e9;
  for (const auto& smp : s) {
    const double d = cut_edge_at(fit, smp.z_mm, 0, 10) - smp.u_mm;
    lo = std::min(lo, d);
    hi = std::max(hi, d);
  }
  EXPECT_LT(lo, 0);
  EXPECT_GT(hi, 0);
  EXPECT_NEAR(-lo, hi, 1e-9);
}

TEST(ProfileFit, ASampleInsideTheLayerIsAsNearAsTheFaceNextToIt) {
  // A surface 68° from vertical, u = −2.5 (1 − z) over a 1 mm layer, and a 45° limit: the one
  // line the limit allows runs from (z 0, u −1) to (z 1, u 0). The layer's edge is that line and
  // its two faces (what the 3-D measure of a layer reads, its closed shell): the sample at the
  // bottom face, 1.5 mm in from the line's end, lies on the layer's bottom face. The farthest is
  // the line's bottom end from the surface, 1.5 / √(1 + 2.5²) = 0.557 mm; along the face to the
  // line's end it read 1.5 mm, and the layering's estimates on the 1M sphere's slopes were 2.3
  // times the layers' measures.
  const Curve shallow = [](double z) { return -2.5 * (1.0 - z); };
  const auto s = sample(shallow, 0, 1, 0.25);
  ProfileFitParams p;
  p.tilt_max_rad = std::numbers::pi / 4;
  const auto fit = fit_profile(s, 0, 1, p);
  ASSERT_EQ(fit.cuts.size(), 1u);
  EXPECT_TRUE(fit.tilt_limited);
  EXPECT_NEAR(fit.cuts[0].u_bottom_mm, -1.0, 1e-9);
  EXPECT_NEAR(fit.cuts[0].u_top_mm, 0.0, 1e-9);
  EXPECT_NEAR(fit.max_deviation_mm, 1.5 / std::sqrt(1.0 + 2.5 * 2.5), 1e-6);
}

TEST(ProfileFit, MissingSamplesMakeALedge) {
  // A vertical wall up to z = 5 inside a 10 mm layer, nothing on this line above it.
  std::vector<ProfileSample> s;
  for (int i = 0; i <= 20; ++i) {
    const double z = 0.5 * i;
    s.push_back({z, 0.0, 0.0, z <= 5.0});
  }
  ProfileFitParams p;
  const auto fit = fit_profile(s, 0, 10, p);
  ASSERT_FALSE(fit.cuts.empty());
  EXPECT_NEAR(cut_edge_at(fit, 10, 0, 10), 0.0, 1e-9);
  // The edge's top corner (z = 10) is 10 − 5.25 above the ledge the surface makes.
  EXPECT_NEAR(fit.max_deviation_mm, 4.75, 1e-9);
  // No sample at all: no cut.
  for (auto& x : s) x.present = false;
  EXPECT_EQ(fit_profile(s, 0, 10, p).shape, ProfileShape::empty);
}

}  // namespace
}  // namespace lamina
