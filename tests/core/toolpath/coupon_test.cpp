// The calibration coupon (coupon.hpp, issue 20): one labelled slot per tilt and feed ratio, each
// cut at the ratio of the separation speed it says, along the path it says, at the tilt it says,
// apart from its neighbours, and through the same post as every sheet.
#include "lamina/core/coupon.hpp"
#include "lamina/core/post.hpp"
#include "toolpath_fixture.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <set>

namespace lamina {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

TEST(CalibrationCoupon, EverySlotIsCutAtItsRatioTiltAndPath) {
  const ToolpathParams params;
  CouponParams c;
  c.thickness_mm = 8.0;
  auto coupon = calibration_coupon(c, aluminium(), params);
  ASSERT_TRUE(coupon) << coupon.error().message;
  ASSERT_EQ(coupon->cuts.size(), 10u);
  ASSERT_EQ(coupon->toolpath.contours.size(), 10u);
  std::set<std::string> labels;
  for (const CouponCut& cut : coupon->cuts) {
    labels.insert(cut.label);
    EXPECT_NEAR(cut.path_mm, 8.0 / std::cos(cut.tilt_rad), 1e-12);
    const double v_s = *separation_feed_mm_per_s(params.jet, aluminium(), params.feed, 8.0, cut.tilt_rad);
    EXPECT_NEAR(cut.separation_feed_mm_per_s, v_s, 1e-9);
    EXPECT_NEAR(cut.feed_mm_per_s, cut.feed_ratio * v_s, 1e-9);
    // The slot itself: a cut move of the asked length, on the top face, at the tilt, at the feed.
    const ToolContour& contour = coupon->toolpath.contours[static_cast<std::size_t>(cut.contour)];
    EXPECT_EQ(contour.label, cut.label);
    int cuts = 0;
    for (std::size_t i = contour.first_move; i < contour.end_move; ++i) {
      const ToolMove& m = coupon->toolpath.moves[i];
      if (m.kind != MoveKind::cut) continue;
      ++cuts;
      const ToolMove& before = coupon->toolpath.moves[i - 1];
      EXPECT_NEAR((m.tip_mm - before.tip_mm).norm(), c.cut_length_mm, 1e-9);
      EXPECT_NEAR(m.tip_mm.z(), 0.0, 1e-12);
      EXPECT_NEAR(std::acos(m.axis.z()), std::abs(cut.tilt_rad), 1e-9);
      EXPECT_NEAR(m.axis.dot((m.tip_mm - before.tip_mm).normalized()), 0.0, 1e-12) << "leans across the travel";
      EXPECT_NEAR(m.feed_mm_per_s, cut.feed_mm_per_s, 1e-12);
      EXPECT_TRUE(m.jet_on);
    }
    EXPECT_EQ(cuts, 1) << cut.label;
  }
  EXPECT_EQ(labels.size(), 10u) << "every slot has its own label";
  EXPECT_TRUE(labels.contains("T30-R0.50")) << *labels.begin();
  // Faster cuts at the same path are faster; the separation cut is the fastest.
  EXPECT_LT(coupon->cuts[0].feed_mm_per_s, coupon->cuts[4].feed_mm_per_s);
  EXPECT_GT(coupon->cuts[0].separation_feed_mm_per_s, coupon->cuts[5].separation_feed_mm_per_s) << "a longer path is slower";
  // Neighbouring slots stay apart at the top and at the bottom (a tilted slot's bottom is offset).
  EXPECT_GE(coupon->width_mm, 10 * c.spacing_mm);
  EXPECT_GT(coupon->toolpath.time.cutting_s, 0.0);
  EXPECT_EQ(coupon->toolpath.time.pierces, 10);

  HeadKinematics head;
  head.rtcp = false;
  auto program = post_program(coupon->toolpath, head, PostParams{});
  ASSERT_TRUE(program) << program.error().message;
  EXPECT_NE(program->text.find("(CONTOUR 7 T30-R0.50 TEST CUT OPEN)"), std::string::npos) << program->text.substr(0, 600);
  EXPECT_EQ(program->contour_lines.size(), 10u);
}

TEST(CalibrationCoupon, TheMachinesFeedLimitsWinAndTheRatioSaysSo) {
  ToolpathParams params;
  params.feed.max_feed_mm_per_s = 5.0;  // far below the separation speed at 4 mm (about 70 mm/s)
  CouponParams c;
  c.thickness_mm = 4.0;
  c.tilts_rad = {0.0};
  auto coupon = calibration_coupon(c, aluminium(), params);
  ASSERT_TRUE(coupon) << coupon.error().message;
  const CouponCut& fastest = coupon->cuts.back();
  EXPECT_NEAR(fastest.feed_mm_per_s, 5.0, 1e-12);
  EXPECT_LT(fastest.feed_ratio, 1.0);
  EXPECT_NEAR(fastest.feed_ratio, 5.0 / fastest.separation_feed_mm_per_s, 1e-12);
}

TEST(CalibrationCoupon, ImpossibleCouponsAreRefusedByValue) {
  const ToolpathParams params;
  CouponParams c;
  c.tilts_rad = {70 * kDeg};
  auto r = calibration_coupon(c, aluminium(), params);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("tilt 70.0 deg is beyond 60 deg"), std::string::npos) << r.error().message;
  c = CouponParams{};
  c.feed_ratios = {0.5, -1};
  r = calibration_coupon(c, aluminium(), params);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("feed ratio -1"), std::string::npos) << r.error().message;
  c = CouponParams{};
  c.thickness_mm = 0;
  EXPECT_FALSE(calibration_coupon(c, aluminium(), params));
  Material unknown;
  unknown.name = "mystery";
  EXPECT_FALSE(calibration_coupon(CouponParams{}, unknown, params)) << "no machinability: no separation speed";
}

}  // namespace
}  // namespace lamina
