// The head's rotary rates (cam/rotary_rates.hpp): a feed that would turn A or C faster than the
// machine can is lowered to what they reach, counting the way a head reaches an axis with the
// least motion (A through zero instead of C through a half turn), and a vertical axis holds C.
#include "cam/rotary_rates.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace lamina::cam_detail {
namespace {

PathPoint line(const Eigen::Vector2d& tip, const Eigen::Vector3d& axis, double feed, double thickness = 10.0) {
  PathPoint p;
  p.tip = Eigen::Vector3d(tip.x(), tip.y(), 0.0);
  p.axis = axis.normalized();
  p.bottom = p.tip - (thickness / p.axis.z()) * p.axis;
  p.feed_mm_per_s = feed;
  return p;
}

// A tilted jet round a circle: its azimuth turns once per revolution, so C turns 2π/n per line.
std::vector<PathPoint> tilted_circle(double radius, int n, double tilt_rad, double feed) {
  std::vector<PathPoint> ring;
  for (int i = 0; i < n; ++i) {
    const double u = 2.0 * std::numbers::pi * i / n;
    const Eigen::Vector2d out(std::cos(u), std::sin(u));
    ring.push_back(line(radius * out, Eigen::Vector3d(std::sin(tilt_rad) * out.x(), std::sin(tilt_rad) * out.y(), std::cos(tilt_rad)), feed));
  }
  return ring;
}

TEST(RotaryRates, ATiltedJetRoundACircleGoesNoFasterThanCTurns) {
  const double c_rate = 2.0;  // rad/s
  auto ring = tilted_circle(10.0, 72, 0.3, 100.0);
  EXPECT_EQ(limit_feeds_to_rotary_rates(ring, 100.0, c_rate), ring.size());
  // Each move: the longer of the tip's and the bottom's travel over the time C takes for 5°.
  const double travel = std::max((ring[1].tip - ring[0].tip).norm(), (ring[1].bottom - ring[0].bottom).norm());
  const double expected = travel / (2.0 * std::numbers::pi / 72 / c_rate);
  for (const PathPoint& p : ring) EXPECT_NEAR(p.feed_mm_per_s, expected, 1e-9);
  // Rates the path does not reach change nothing.
  auto fast = tilted_circle(10.0, 72, 0.3, 1.0);
  EXPECT_EQ(limit_feeds_to_rotary_rates(fast, 100.0, c_rate), 0u);
  EXPECT_EQ(fast[5].feed_mm_per_s, 1.0);
}

TEST(RotaryRates, AReversedLeanSwingsAThroughZeroRatherThanCThroughAHalfTurn) {
  const double small = 0.002;  // rad
  std::vector<PathPoint> pts{line({0, 0}, {std::sin(small), 0, 1}, 50.0), line({1, 0}, {-std::sin(small), 0, 1}, 50.0),
                             line({2, 0}, {-std::sin(small), 0, 1}, 50.0)};
  const double a_rate = 1.0, c_rate = 1.0;
  limit_feeds_to_rotary_rates(pts, a_rate, c_rate);
  // A from +0.002 to -0.002 rad takes 4 ms: 1 mm of travel in it is 250 mm/s, above the feed.
  // Counted as a half turn of C (3.1 s) it would have been 0.32 mm/s.
  EXPECT_EQ(pts[0].feed_mm_per_s, 50.0);
  EXPECT_EQ(pts[1].feed_mm_per_s, 50.0);
}

TEST(RotaryRates, AVerticalJetHoldsCAndTheCornerFactorCounts) {
  // Vertical lines round a square: no rotary motion at all.
  std::vector<PathPoint> square{line({0, 0}, {0, 0, 1}, 80.0), line({10, 0}, {0, 0, 1}, 80.0), line({10, 10}, {0, 0, 1}, 80.0),
                                line({0, 10}, {0, 0, 1}, 80.0)};
  EXPECT_EQ(limit_feeds_to_rotary_rates(square, 0.1, 0.1), 0u);
  // A tilting move slowed at a corner: the fastest feed is the A rate's, before the corner factor.
  std::vector<PathPoint> tilt{line({0, 0}, {0, 0, 1}, 80.0), line({1, 0}, {0, std::sin(0.1), std::cos(0.1)}, 80.0)};
  tilt[0].corner_factor = tilt[1].corner_factor = 0.5;
  limit_feeds_to_rotary_rates(tilt, 1.0, 1.0);
  const double travel = std::max((tilt[1].tip - tilt[0].tip).norm(), (tilt[1].bottom - tilt[0].bottom).norm());
  EXPECT_NEAR(tilt[0].feed_mm_per_s * 0.5, travel / 0.1, 1e-9) << "the move's feed, corner factor and all, is the A rate's";
}

}  // namespace
}  // namespace lamina::cam_detail
