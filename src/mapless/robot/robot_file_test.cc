#include "mapless/robot/robot_file.h"

#include <gtest/gtest.h>

#include "mapless/core/check.h"

namespace mapless::robot {
namespace {

TEST(RobotFile, DefaultsAreTheRosConventions) {
  const RobotFile r = ParseRobotFile("{}", "robot.yaml");
  EXPECT_EQ(r.middleware, "ros1");
  EXPECT_EQ(r.Resolve(r.topics.image), "/camera/image_raw");
  EXPECT_EQ(r.Resolve(r.topics.odometry), "/odom");
  EXPECT_EQ(r.Resolve(r.topics.cmd_vel), "/cmd_vel");
  EXPECT_FALSE(r.use_sim_time);
  EXPECT_EQ(r.threads, 2);
  EXPECT_EQ(ParseRobotFile("threads: 1\n", "robot.yaml").threads, 1);
}

TEST(RobotFile, NamespaceAppliesToRelativeTopicsOnly) {
  const RobotFile r = ParseRobotFile(
      "namespace: robot1\ntopics: {image: front/image_raw, cmd_vel: /base/cmd_vel}\n"
      "limits: {max_speed_mps: 0.5, max_turn_rate_radps: 0.8}\ncamera: {mount: rotated_180}\n",
      "r.yaml");
  EXPECT_EQ(r.Resolve(r.topics.image), "/robot1/front/image_raw");
  EXPECT_EQ(r.Resolve(r.topics.cmd_vel), "/base/cmd_vel");
  EXPECT_EQ(r.max_speed_mps, 0.5);
  EXPECT_EQ(r.mount, CameraMount::kRotated180);
}

void ExpectError(const std::string& text, const std::string& needle) {
  try {
    ParseRobotFile(text, "bad.yaml");
    FAIL() << "accepted: " << text;
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("bad.yaml"), std::string::npos) << what;
    EXPECT_NE(what.find(needle), std::string::npos) << what;
  }
}

TEST(RobotFile, HowLongABlockedRobotWaitsIsASetting) {
  EXPECT_EQ(ParseRobotFile("{}", "r.yaml").Loop().max_blocked_s, 60.0);
  EXPECT_EQ(ParseRobotFile("safety: {max_blocked_s: 0}\n", "r.yaml").Loop().max_blocked_s, 0.0);
  EXPECT_EQ(ParseRobotFile("safety: {max_blocked_s: 300}\n", "r.yaml").max_blocked_s, 300.0);
  ExpectError("safety: {max_blocked_s: -1}\n", "max_blocked_s");
  ExpectError("safety: {max_blocked_s: .nan}\n", "max_blocked_s");
}

TEST(RobotFile, BadFieldsAreNamed) {
  ExpectError("topic: {image: x}\n", "topic");
  ExpectError("topics: {imagee: x}\n", "imagee");
  ExpectError("middleware: ros3\n", "ros3");
  ExpectError("topics: {image: 'a b'}\n", "topics.image");
  ExpectError("topics: {cmd_vel: ''}\n", "topics.cmd_vel");
  ExpectError("limits: {max_speed_mps: -1}\n", "limits.max_speed_mps");
  ExpectError("limits: {max_speed_mps: .nan}\n", "limits.max_speed_mps");
  ExpectError("camera: {mount: sideways}\n", "sideways");
  ExpectError("safety: {camera_timeout_s: 0}\n", "safety.camera_timeout_s");
  ExpectError("[1, 2]\n", "bad.yaml");
  ExpectError("obstacles: {on_obstacle: swerve}\n", "on_obstacle");
  ExpectError("obstacles: {region_width: 0}\n", "obstacles.region_width");
  ExpectError("obstacles: {horizon: 0.8}\n", "obstacles.horizon");  // below region_top
  ExpectError("threads: 3\n", "threads");
  ExpectError("threads: two\n", "threads");
  // Issue 40: a key named twice, and one topic for two roles.
  ExpectError("middleware: ros2\nmiddleware: ros1\n", "duplicate key 'middleware'");
  ExpectError("topics: {cmd_vel: camera/image_raw}\n", "topics.cmd_vel");
  ExpectError("namespace: r1\ntopics: {image: /r1/cam, status: cam}\n", "also the image topic");
}

TEST(RobotFile, ObstacleWatchSettings) {
  const RobotFile r = ParseRobotFile(
      "obstacles: {on_obstacle: stop, region_top: 0.8, region_width: 0.3, horizon: 0.4}\n",
      "robot.yaml");
  EXPECT_TRUE(r.obstacle.enabled);
  EXPECT_DOUBLE_EQ(r.obstacle.region_top, 0.8);
  EXPECT_DOUBLE_EQ(r.obstacle.region_width, 0.3);
  EXPECT_DOUBLE_EQ(r.obstacle.horizon, 0.4);
  EXPECT_TRUE(ParseRobotFile("{}\n", "robot.yaml").obstacle.enabled);  // stop unless told off
  EXPECT_FALSE(ParseRobotFile("{}\n", "robot.yaml").obstacle_baseline_given);
  const RobotFile b = ParseRobotFile("obstacles: {baseline_m: 0.2}\n", "robot.yaml");
  EXPECT_TRUE(b.obstacle_baseline_given);
  EXPECT_DOUBLE_EQ(b.obstacle.baseline_m, 0.2);
  EXPECT_FALSE(b.obstacle_max_unchecked_given);
  const RobotFile u = ParseRobotFile("obstacles: {max_unchecked_m: 0.4}\n", "robot.yaml");
  EXPECT_TRUE(u.obstacle_max_unchecked_given);
  EXPECT_DOUBLE_EQ(u.obstacle.max_unchecked_m, 0.4);
  EXPECT_THROW(ParseRobotFile("obstacles: {max_unchecked_m: -1}\n", "robot.yaml"), InputError);
  EXPECT_FALSE(ParseRobotFile("obstacles: {on_obstacle: off}\n", "robot.yaml").obstacle.enabled);
  EXPECT_FALSE(ParseRobotFile("{}\n", "robot.yaml").obstacle.avoid);
  const RobotFile a =
      ParseRobotFile("obstacles: {on_obstacle: avoid, region_half_width_m: 0.35}\n", "robot.yaml");
  EXPECT_TRUE(a.obstacle.enabled);
  EXPECT_TRUE(a.obstacle.avoid);
  EXPECT_DOUBLE_EQ(a.obstacle.region_half_width_m, 0.35);
  ExpectError("obstacles: {region_half_width_m: 0}\n", "region_half_width_m");
  EXPECT_DOUBLE_EQ(
      ParseRobotFile("obstacles: {region_far_m: 3.5}\n", "robot.yaml").obstacle.region_far_m, 3.5);
  ExpectError("obstacles: {region_far_m: -1}\n", "region_far_m");
  const RobotFile h =
      ParseRobotFile("obstacles: {hidden_drop: 0, hidden_min_reference: 0.7}\n", "robot.yaml");
  EXPECT_DOUBLE_EQ(h.obstacle.hidden_drop, 0.0);
  EXPECT_DOUBLE_EQ(h.obstacle.hidden_min_reference, 0.7);
  ExpectError("obstacles: {hidden_drop: 1.5}\n", "hidden_drop");
  // The creep that checks unchecked ground (issue 65): how far and how fast; 0 m: stop at once.
  const RobotFile c =
      ParseRobotFile("obstacles: {creep_m: 0, creep_speed_mps: 0.05}\n", "robot.yaml");
  EXPECT_DOUBLE_EQ(c.obstacle.creep_m, 0.0);
  EXPECT_DOUBLE_EQ(c.obstacle.creep_speed_mps, 0.05);
  EXPECT_DOUBLE_EQ(ParseRobotFile("{}\n", "robot.yaml").obstacle.creep_m, 0.3);
  ExpectError("obstacles: {creep_m: 5}\n", "creep_m");
  ExpectError("obstacles: {creep_speed_mps: 0}\n", "creep_speed_mps");
}

TEST(RobotFile, TheCommentedExampleLoadsWithItsStatedValues) {
  const RobotFile r =
      LoadRobotFile(std::string(MAPLESS_SOURCE_DIR) + "/config/robots/turtlebot.yaml");
  EXPECT_DOUBLE_EQ(r.obstacle.creep_m, 0.3);
  EXPECT_DOUBLE_EQ(r.obstacle.creep_speed_mps, 0.1);
  EXPECT_DOUBLE_EQ(r.obstacle.hidden_drop, 0.3);
  EXPECT_DOUBLE_EQ(r.obstacle.hidden_min_reference, 0.55);
  EXPECT_DOUBLE_EQ(r.obstacle.min_blocked_fraction, 0.15);
}

}  // namespace
}  // namespace mapless::robot
