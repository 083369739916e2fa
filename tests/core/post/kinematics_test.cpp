// AC head kinematics: hand cases of the sign conventions, inverse ∘ forward, the vertical hold,
// the choice between the two solutions, limits and bad input.
#include "lamina/core/kinematics.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

namespace {

using lamina::AxisPose;
using lamina::HeadKinematics;
using lamina::inverse_kinematics;
using lamina::tool_axis_at;

constexpr double deg = std::numbers::pi / 180.0;

void expect_vec(const Eigen::Vector3d& got, const Eigen::Vector3d& want, double tol) {
  EXPECT_NEAR((got - want).norm(), 0.0, tol) << "got " << got.transpose() << " want " << want.transpose();
}

TEST(Kinematics, HandCasesOfTheSignConventions) {
  HeadKinematics h;
  // Rx(+90°)·ẑ = −ŷ; then Rz(+90°)·(−ŷ) = +x̂.
  expect_vec(tool_axis_at(90 * deg, 0.0, h), {0, -1, 0}, 1e-15);
  expect_vec(tool_axis_at(90 * deg, 90 * deg, h), {1, 0, 0}, 1e-15);
  expect_vec(tool_axis_at(0.0, 37 * deg, h), {0, 0, 1}, 1e-15);
  h.a_sign = -1;
  expect_vec(tool_axis_at(90 * deg, 0.0, h), {0, 1, 0}, 1e-15);
  h.a_sign = 1;
  h.c_sign = -1;
  expect_vec(tool_axis_at(90 * deg, 90 * deg, h), {-1, 0, 0}, 1e-15);
  h.c_sign = 1;
  h.c_offset_rad = 90 * deg;
  expect_vec(tool_axis_at(90 * deg, 0.0, h), {1, 0, 0}, 1e-15);
}

TEST(Kinematics, PivotShiftIsZeroAtAZeroAndFollowsTheAxis) {
  HeadKinematics h;
  h.rtcp = false;
  h.pivot_mm = 100.0;
  auto vertical = inverse_kinematics({10, 20, 0}, {0, 0, 1}, 0.0, h);
  ASSERT_TRUE(vertical);
  EXPECT_DOUBLE_EQ(vertical->x_mm, 10);
  EXPECT_DOUBLE_EQ(vertical->y_mm, 20);
  EXPECT_DOUBLE_EQ(vertical->z_mm, 0);
  // Axis along +x at 30° tilt: pivot 100 mm up that axis, minus the vertical 100 mm.
  const Eigen::Vector3d axis(std::sin(30 * deg), 0, std::cos(30 * deg));
  auto p = inverse_kinematics({10, 20, 0}, axis, 0.0, h);
  ASSERT_TRUE(p);
  EXPECT_NEAR(p->x_mm, 10 + 50.0, 1e-12);
  EXPECT_NEAR(p->y_mm, 20, 1e-12);
  EXPECT_NEAR(p->z_mm, 100 * std::cos(30 * deg) - 100, 1e-12);
  h.rtcp = true;
  auto t = inverse_kinematics({10, 20, 0}, axis, 0.0, h);
  ASSERT_TRUE(t);
  EXPECT_DOUBLE_EQ(t->x_mm, 10);
  EXPECT_DOUBLE_EQ(t->z_mm, 0);
}

TEST(Kinematics, InverseOfForwardIsIdentityForRandomPoses) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int signs = 0; signs < 4; ++signs) {
    HeadKinematics h;
    h.rtcp = false;
    h.a_sign = signs & 1 ? -1 : 1;
    h.c_sign = signs & 2 ? -1 : 1;
    h.c_offset_rad = 0.3 * signs;
    for (int i = 0; i < 500; ++i) {
      AxisPose p{100 * u(rng), 100 * u(rng), 20 * u(rng), 59 * deg * u(rng), 700 * deg * u(rng)};
      if (std::abs(p.a_rad) < 1e-3) continue;
      const lamina::TipPose tp = lamina::forward_kinematics(p, h);
      // Previous C close to the pose's own C: the inverse must return exactly this pose.
      auto back = inverse_kinematics(tp.tip_mm, tp.axis, p.c_rad + 0.4 * u(rng), h);
      ASSERT_TRUE(back) << back.error().message;
      EXPECT_NEAR(back->a_rad, p.a_rad, 1e-9);
      EXPECT_NEAR(back->c_rad, p.c_rad, 1e-9);
      EXPECT_NEAR(back->x_mm, p.x_mm, 1e-9);
      EXPECT_NEAR(back->y_mm, p.y_mm, 1e-9);
      EXPECT_NEAR(back->z_mm, p.z_mm, 1e-9);
    }
  }
}

TEST(Kinematics, ChoosesTheSolutionNearestThePreviousC) {
  HeadKinematics h;
  const Eigen::Vector3d axis = tool_axis_at(20 * deg, 10 * deg, h);
  auto near = inverse_kinematics({0, 0, 0}, axis, 5 * deg, h);
  ASSERT_TRUE(near);
  EXPECT_NEAR(near->a_rad, 20 * deg, 1e-12);
  EXPECT_NEAR(near->c_rad, 10 * deg, 1e-12);
  // Previous C at 170°: (−20°, 190°) is 20° away, (20°, 10°) 160°.
  auto flipped = inverse_kinematics({0, 0, 0}, axis, 170 * deg, h);
  ASSERT_TRUE(flipped);
  EXPECT_NEAR(flipped->a_rad, -20 * deg, 1e-12);
  EXPECT_NEAR(flipped->c_rad, 190 * deg, 1e-12);
  // Unwound: previous C at 3 turns.
  auto wound = inverse_kinematics({0, 0, 0}, axis, 1085 * deg, h);
  ASSERT_TRUE(wound);
  EXPECT_NEAR(wound->c_rad, 1090 * deg, 1e-12);
  // With A limited to ≥ 0 only the first solution is allowed, however far its C.
  h.a_min_rad = 0.0;
  auto limited = inverse_kinematics({0, 0, 0}, axis, 170 * deg, h);
  ASSERT_TRUE(limited);
  EXPECT_NEAR(limited->a_rad, 20 * deg, 1e-12);
  EXPECT_NEAR(limited->c_rad, 10 * deg, 1e-12);
}

TEST(Kinematics, VerticalAxisHoldsC) {
  HeadKinematics h;
  auto p = inverse_kinematics({1, 2, 3}, {0, 0, 1}, 123 * deg, h);
  ASSERT_TRUE(p);
  EXPECT_EQ(p->a_rad, 0.0);
  EXPECT_EQ(p->c_rad, 123 * deg);
  // Just under the hold threshold: still held; just above: C follows the axis.
  const double tiny = 0.5 * h.hold_c_below_rad;
  auto q = inverse_kinematics({1, 2, 3}, {std::sin(tiny), 0, std::cos(tiny)}, -40 * deg, h);
  ASSERT_TRUE(q);
  EXPECT_EQ(q->c_rad, -40 * deg);
  const Eigen::Vector3d leaning = tool_axis_at(1e-3, 90 * deg, h);
  auto r = inverse_kinematics({1, 2, 3}, leaning, -40 * deg, h);
  ASSERT_TRUE(r);
  // (−A, −90°) is 50° from the previous C, (A, 90°) 130°.
  EXPECT_NEAR(r->c_rad, -90 * deg, 1e-9);
  EXPECT_NEAR(r->a_rad, -1e-3, 1e-12);
  expect_vec(tool_axis_at(r->a_rad, r->c_rad, h), leaning, 1e-12);
}

TEST(Kinematics, TiltBeyondTheLimitsIsAnErrorNamingBoth) {
  HeadKinematics h;  // ±60°
  auto p = inverse_kinematics({0, 0, 0}, tool_axis_at(65 * deg, 0.0, h), 0.0, h);
  ASSERT_FALSE(p);
  EXPECT_NE(p.error().message.find("65.000"), std::string::npos) << p.error().message;
  EXPECT_NE(p.error().message.find("60.000"), std::string::npos) << p.error().message;
  EXPECT_TRUE(inverse_kinematics({0, 0, 0}, tool_axis_at(60 * deg, 0.0, h), 0.0, h));
}

TEST(Kinematics, NonUnitAxisIsAnError) {
  HeadKinematics h;
  auto p = inverse_kinematics({0, 0, 0}, {0, 0, 1.01}, 0.0, h);
  ASSERT_FALSE(p);
  EXPECT_EQ(p.error().code, lamina::ErrorCode::invalid_argument);
  EXPECT_NE(p.error().message.find("unit"), std::string::npos);
  EXPECT_FALSE(inverse_kinematics({0, 0, 0}, {0, 0, std::nan("")}, 0.0, h));
}

}  // namespace
