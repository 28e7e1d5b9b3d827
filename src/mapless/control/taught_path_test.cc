#include "mapless/control/taught_path.h"

#include <gtest/gtest.h>

#include <cmath>

#include "mapless/core/check.h"

namespace mapless::control {
namespace {

// Drives the pursuit's commands with exact odometry; returns the poses visited.
std::vector<Pose2> Drive(TaughtPathPursuit* pursuit, Pose2 pose, int max_steps) {
  std::vector<Pose2> visited{pose};
  for (int i = 0; i < max_steps; ++i) {
    const std::optional<Twist2> c = pursuit->Command(pose, 0.2);
    if (!c) break;
    pose = IntegrateTwist(pose, *c, 0.1);
    visited.push_back(pose);
  }
  return visited;
}

// A left turn taught in one odometry frame, repeated from another (rotated and shifted): the
// robot passes within reach of every taught pose, in the repeat's frame.
TEST(TaughtPathPursuit, DrivesATaughtTurnFromAnotherOdometryFrame) {
  std::vector<Pose2> taught;
  for (int i = 1; i <= 8; ++i) {
    const double a = 0.2 * i;  // a quarter circle of radius 2 m, then on
    taught.push_back({2.0 * std::sin(a), 2.0 - 2.0 * std::cos(a), a});
  }
  const Pose2 anchor_taught{0.0, 0.0, 0.0};
  const Pose2 anchor_odometry{5.0, -3.0, 1.0};
  TaughtPathPursuit pursuit(taught, anchor_taught, anchor_odometry, TaughtPathOptions{});
  const std::vector<Pose2> visited = Drive(&pursuit, anchor_odometry, 600);
  EXPECT_EQ(pursuit.target(), pursuit.size());  // every pose reached or passed
  const Pose2 map = anchor_odometry * anchor_taught.Inverse();
  for (const Pose2& t : taught) {
    const Pose2 want = map * t;
    double best = 1e9;
    for (const Pose2& p : visited) best = std::min(best, p.DistanceTo(want));
    EXPECT_LT(best, 0.35) << t.x_m << ", " << t.y_m;
  }
  EXPECT_GT(pursuit.driven_m(), 2.5);
}

TEST(TaughtPathPursuit, TurnsInPlaceToATargetFarOffItsHeadingAndStopsAtTheDistanceLimit) {
  TaughtPathOptions o;
  o.max_distance_m = 1.0;
  // The target 63 degrees to the left: turn in place first (no forward speed).
  TaughtPathPursuit left({{1.0, 2.0, 0.0}, {1.0, 6.0, 0.0}}, {}, {}, o);
  const std::optional<Twist2> c = left.Command({0.0, 0.0, 0.0}, 0.2);
  ASSERT_TRUE(c.has_value());
  EXPECT_EQ(c->v_mps, 0.0);
  EXPECT_GT(c->omega_radps, 0.0);
  // Driving on: the stretch ends after max_distance_m of odometry, before the far pose.
  const std::vector<Pose2> visited = Drive(&left, {0.0, 0.0, 0.0}, 1000);
  EXPECT_LE(left.driven_m(), 1.0 + 0.05);
  EXPECT_LT(visited.back().y_m, 1.2);
  TaughtPathOptions bad;
  bad.reached_m = 0.0;
  EXPECT_THROW(bad.Validate(), InputError);
}

}  // namespace
}  // namespace mapless::control
