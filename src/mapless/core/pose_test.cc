#include "mapless/core/pose.h"

#include <gtest/gtest.h>

namespace mapless {
namespace {

TEST(Pose2, ComposeWithInverseIsIdentity) {
  const Pose2 p{1.5, -2.0, 0.7};
  const Pose2 id = p * p.Inverse();
  EXPECT_NEAR(id.x_m, 0.0, 1e-12);
  EXPECT_NEAR(id.y_m, 0.0, 1e-12);
  EXPECT_NEAR(id.theta_rad, 0.0, 1e-12);
}

TEST(Pose2, ApplyRotatesThenTranslates) {
  const Pose2 p{1.0, 2.0, kPi / 2};
  double x = 0;
  double y = 0;
  p.Apply(1.0, 0.0, &x, &y);
  EXPECT_NEAR(x, 1.0, 1e-12);
  EXPECT_NEAR(y, 3.0, 1e-12);
}

TEST(WrapAngle, MapsIntoHalfOpenInterval) {
  EXPECT_NEAR(WrapAngle(3 * kPi), kPi, 1e-12);
  EXPECT_NEAR(WrapAngle(-3 * kPi), kPi, 1e-12);
  EXPECT_NEAR(WrapAngle(0.5), 0.5, 1e-12);
  EXPECT_NEAR(WrapAngle(2 * kPi + 0.1), 0.1, 1e-12);
}

TEST(IntegrateTwist, QuarterCircleEndsOnTheArc) {
  // v = 1 m/s, omega = pi/2 rad/s for 1 s: a quarter circle of radius 2/pi.
  const Pose2 end = IntegrateTwist(Pose2{}, Twist2{1.0, kPi / 2}, 1.0);
  const double r = 2.0 / kPi;
  EXPECT_NEAR(end.x_m, r, 1e-12);
  EXPECT_NEAR(end.y_m, r, 1e-12);
  EXPECT_NEAR(end.theta_rad, kPi / 2, 1e-12);
}

TEST(IntegrateTwist, SmallStepsComposeToTheSameArc) {
  Pose2 p;
  for (int i = 0; i < 1000; ++i) p = IntegrateTwist(p, Twist2{0.5, 0.3}, 0.01);
  const Pose2 one = IntegrateTwist(Pose2{}, Twist2{0.5, 0.3}, 10.0);
  EXPECT_NEAR(p.x_m, one.x_m, 1e-9);
  EXPECT_NEAR(p.y_m, one.y_m, 1e-9);
}

}  // namespace
}  // namespace mapless
