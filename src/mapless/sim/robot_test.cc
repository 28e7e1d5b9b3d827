#include "mapless/sim/robot.h"

#include <gtest/gtest.h>

#include <cmath>

namespace mapless::sim {
namespace {

RobotOptions NoNoise() {
  RobotOptions o;
  o.odom_scale_error = 0.0;
  o.odom_noise_v_mps = 0.0;
  o.odom_noise_omega_radps = 0.0;
  return o;
}

TEST(DiffDriveRobot, CommandedTwistTracesTheExpectedArcWithinOnePercent) {
  RobotOptions o = NoNoise();
  o.max_accel_mps2 = 1e6;  // no ramp: the arc starts at once
  o.max_alpha_radps2 = 1e6;
  DiffDriveRobot robot(Pose2{}, o, 1);
  const double v = 0.5, omega = 0.4, duration = 6.0;
  robot.SetCommand(Twist2{v, omega});
  for (int i = 0; i < 600; ++i) robot.Step(0.01);
  const double r = v / omega;
  const double th = omega * duration;
  const double ex = r * std::sin(th);
  const double ey = r * (1 - std::cos(th));
  const double err = std::hypot(robot.pose().x_m - ex, robot.pose().y_m - ey);
  EXPECT_LT(err, 0.01 * v * duration) << "arc length " << v * duration;
  EXPECT_NEAR(robot.pose().theta_rad, WrapAngle(th), 0.01 * th);
}

TEST(DiffDriveRobot, WithAccelerationLimitsTheSteadyArcHasRadiusVOverOmega) {
  DiffDriveRobot robot(Pose2{}, NoNoise(), 1);
  robot.SetCommand(Twist2{0.4, 0.5});
  for (int i = 0; i < 200; ++i) robot.Step(0.01);  // ramp up
  const Pose2 p0 = robot.pose();
  // Centre of the circle from the current pose: radius v/omega to the left.
  const double r = 0.4 / 0.5;
  const double cx = p0.x_m - r * std::sin(p0.theta_rad);
  const double cy = p0.y_m + r * std::cos(p0.theta_rad);
  for (int i = 0; i < 800; ++i) {
    robot.Step(0.01);
    const double d = std::hypot(robot.pose().x_m - cx, robot.pose().y_m - cy);
    ASSERT_NEAR(d, r, 0.01 * r) << "step " << i;
  }
}

TEST(DiffDriveRobot, RespectsVelocityAndAccelerationLimits) {
  RobotOptions o = NoNoise();
  o.max_v_mps = 0.5;
  o.max_accel_mps2 = 1.0;
  DiffDriveRobot robot(Pose2{}, o, 1);
  robot.SetCommand(Twist2{5.0, 0.0});
  robot.Step(0.1);
  EXPECT_NEAR(robot.velocity().v_mps, 0.1, 1e-9);
  for (int i = 0; i < 100; ++i) robot.Step(0.1);
  EXPECT_NEAR(robot.velocity().v_mps, 0.5, 1e-9);
}

TEST(DiffDriveRobot, MotionNoiseIsSeededAndPerturbsThePath) {
  RobotOptions o = NoNoise();
  o.motion_noise_v_frac = 0.2;
  o.motion_noise_omega_frac = 0.2;
  auto run = [&](std::uint64_t seed) {
    DiffDriveRobot robot(Pose2{}, o, seed);
    for (int k = 0; k < 50; ++k) {
      robot.SetCommand(Twist2{0.5, 0.2});
      for (int i = 0; i < 10; ++i) robot.Step(0.01);
    }
    return robot.pose();
  };
  const Pose2 a = run(3), b = run(3), c = run(4);
  EXPECT_EQ(a.x_m, b.x_m);
  EXPECT_EQ(a.y_m, b.y_m);
  EXPECT_GT(a.DistanceTo(c), 1e-3);
}

TEST(DiffDriveRobot, OdometryDriftsAwayFromGroundTruth) {
  RobotOptions o;  // default odometry errors
  DiffDriveRobot robot(Pose2{}, o, 9);
  robot.SetCommand(Twist2{0.5, 0.1});
  for (int i = 0; i < 2000; ++i) robot.Step(0.01);
  const double drift = robot.pose().DistanceTo(robot.odometry());
  EXPECT_GT(drift, 0.01);
  EXPECT_LT(drift, 1.0);
}

}  // namespace
}  // namespace mapless::sim
