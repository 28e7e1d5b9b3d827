#include "mapless/sim/simulation.h"

#include <gtest/gtest.h>

#include <opencv2/features2d.hpp>

#include "mapless/sim/driver.h"

namespace mapless::sim {
namespace {

// Poses along a scenario's taught path, from a clean drive without rendering.
std::vector<Pose2> TaughtPoses(const Scenario& s) {
  DriveOptions o;
  o.render_frames = false;
  std::vector<Pose2> poses;
  DriveTaughtPath(s, o, [&](const DriveFrame& f) { poses.push_back(f.truth); });
  return poses;
}

TEST(Simulation, DriveWithASeedIsDeterministic) {
  Scenario s = LoadScenario("wide_left_turn_offset_start");
  s.robot.motion_noise_v_frac = 0.2;
  s.robot.motion_noise_omega_frac = 0.2;
  DriveOptions o;
  o.seed = 77;
  o.render_frames = false;
  std::vector<Pose2> a, b;
  DriveTaughtPath(s, o, [&](const DriveFrame& f) { a.push_back(f.truth); });
  DriveTaughtPath(s, o, [&](const DriveFrame& f) { b.push_back(f.truth); });
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    ASSERT_EQ(a[i].x_m, b[i].x_m);
    ASSERT_EQ(a[i].y_m, b[i].y_m);
    ASSERT_EQ(a[i].theta_rad, b[i].theta_rad);
  }
}

TEST(Simulation, EveryBuiltinTaughtPathIsDrivenToItsEndWithoutCollision) {
  for (const auto& name : BuiltinScenarioNames()) {
    const Scenario s = LoadScenario(name);
    DriveOptions o;
    o.render_frames = false;
    Pose2 last;
    const DriveSummary summary =
        DriveTaughtPath(s, o, [&](const DriveFrame& f) { last = f.truth; });
    EXPECT_TRUE(summary.completed) << name << ": " << summary.status;
    EXPECT_FALSE(summary.collided) << name << ": " << summary.status;
    // The whole path was driven (a closed loop passes its end point early on, too).
    EXPECT_GT(summary.distance_m, 0.9 * s.PathLength()) << name;
    // The robot ends at the last waypoint of the path.
    Eigen::Vector2d end(s.teach_start.x_m, s.teach_start.y_m);
    for (const auto& step : s.teach_path) {
      if (step.kind == PathStep::Kind::kGoTo) end = step.target;
    }
    EXPECT_LT(std::hypot(last.x_m - end.x(), last.y_m - end.y()), 0.1) << name;
  }
}

TEST(Simulation, OrbFindsAtLeast300KeypointsOnTypicalFramesOfTexturedScenes) {
  auto orb = cv::ORB::create(500);
  for (const auto& name : BuiltinScenarioNames()) {
    if (name.find("low_texture") != std::string::npos) continue;
    const Scenario s = LoadScenario(name);
    const std::vector<Pose2> poses = TaughtPoses(s);
    Simulation sim(s.world, s.camera, {}, 1);
    sim.AddRobot(poses.front(), s.robot);
    std::vector<int> counts;
    for (int k = 0; k < 5; ++k) {
      sim.PlaceRobot(0, poses[static_cast<std::size_t>(k) * (poses.size() - 1) / 4]);
      std::vector<cv::KeyPoint> kp;
      orb->detect(sim.RenderClean(0), kp);
      counts.push_back(static_cast<int>(kp.size()));
    }
    std::sort(counts.begin(), counts.end());
    EXPECT_GE(counts[2], 300) << name << " median ORB keypoints";
    EXPECT_GE(counts[0], 200) << name << " fewest ORB keypoints";
  }
}

TEST(Simulation, LowTextureSceneGivesClearlyFewerFeaturesThanItsTexturedTwin) {
  // Table I's two 10 m indoor paths: plain walls and floor against brick and tiles.
  auto orb = cv::ORB::create(500);
  auto mean_count = [&](const std::string& name) {
    const Scenario s = LoadScenario(name);
    const std::vector<Pose2> poses = TaughtPoses(s);
    double sum = 0;
    Simulation view(s.world, s.camera, {}, 1);
    view.AddRobot(poses.front(), s.robot);
    for (int k = 0; k < 5; ++k) {
      view.PlaceRobot(0, poses[static_cast<std::size_t>(k) * (poses.size() - 1) / 4]);
      std::vector<cv::KeyPoint> kp;
      orb->detect(view.RenderClean(0), kp);
      sum += static_cast<double>(kp.size());
    }
    return sum / 5.0;
  };
  const double low = mean_count("table1_sharp_turn_low_texture");
  const double rich = mean_count("table1_almost_straight");
  EXPECT_LT(low, 0.7 * rich) << "low " << low << " rich " << rich;
  EXPECT_GT(low, 100.0) << "the low-texture path must still be followable";
}

TEST(Simulation, RobotsSeeEachOther) {
  const Scenario s = LoadScenario("corridor_25m");
  Simulation alone(s.world, s.camera, {}, 1);
  alone.AddRobot(s.teach_start, s.robot);
  Simulation pair(s.world, s.camera, {}, 1);
  pair.AddRobot(s.teach_start, s.robot);
  Pose2 ahead = s.teach_start * Pose2{1.5, 0.0, 0.0};
  pair.AddRobot(ahead, s.robot);
  cv::Mat diff;
  cv::absdiff(alone.RenderClean(0), pair.RenderClean(0), diff);
  // The leader 1.5 m ahead (0.4 m wide, 0.5 m tall) covers a patch in the image centre.
  EXPECT_GT(cv::countNonZero(diff(cv::Rect(140, 100, 40, 60)) > 20), 400);
}

TEST(Simulation, DrivingIntoAWallIsACollisionEventAndTheRobotStops) {
  const Scenario s = LoadScenario("corridor_straight_3p5m");
  Simulation sim(s.world, s.camera, {}, 1);
  const int r = sim.AddRobot(s.teach_start, s.robot);
  for (int i = 0; i < 200 && !sim.collided(r); ++i) {
    sim.SetCommand(r, Twist2{0.8, 0.8});  // circles into the side wall
    sim.Advance(0.1);
  }
  ASSERT_TRUE(sim.collided(r));
  EXPECT_EQ(sim.collisions().front().with, "obstacle");
  const Pose2 at = sim.robot(r).pose();
  sim.Advance(1.0);
  EXPECT_EQ(sim.robot(r).pose().x_m, at.x_m);
  EXPECT_LT(ClearanceTo(s.world, at.x_m, at.y_m), s.robot.radius_m + 1e-9);
}

// A box on the path that is taken away at 3 s: seen and in the way before, gone after.
TEST(Simulation, TimedObjectsAppearAndLeaveAtTheirTimes) {
  const Scenario s = LoadScenario("corridor_25m");
  World world = s.world;
  WorldObject box;
  box.kind = ObjectKind::kBox;
  const Pose2 ahead = s.teach_start * Pose2{1.0, 0.0, 0.0};
  box.center = {ahead.x_m, ahead.y_m};
  box.size_m = {0.4, 0.6};
  box.height_m = 0.5;
  box.leaves_s = 3.0;
  world.objects.push_back(box);
  WorldObject late = box;  // put down at 2 s, behind the robot
  const Pose2 behind = s.teach_start * Pose2{-1.0, 0.0, 0.0};
  late.center = {behind.x_m, behind.y_m};
  late.appears_s = 2.0;
  late.leaves_s = std::numeric_limits<double>::infinity();
  world.objects.push_back(late);
  Simulation sim(world, s.camera, {}, 1);
  const int r = sim.AddRobot(s.teach_start, s.robot);
  Simulation empty(s.world, s.camera, {}, 1);
  empty.AddRobot(s.teach_start, s.robot);
  cv::Mat diff;
  cv::absdiff(sim.RenderClean(r), empty.RenderClean(0), diff);
  EXPECT_GT(cv::countNonZero(diff > 20), 1000);  // the box is in view
  EXPECT_EQ(sim.world().objects.size(), s.world.objects.size() + 1);
  sim.Advance(2.5);
  EXPECT_EQ(sim.world().objects.size(), s.world.objects.size() + 2);
  sim.Advance(0.6);  // 3.1 s: the box has gone
  EXPECT_EQ(sim.world().objects.size(), s.world.objects.size() + 1);
  cv::absdiff(sim.RenderClean(r), empty.RenderClean(0), diff);
  EXPECT_EQ(cv::countNonZero(diff > 20), 0);  // the late one is behind the camera
  // Driving through where the box stood is no collision any more.
  for (int i = 0; i < 30; ++i) {
    sim.SetCommand(r, Twist2{0.5, 0.0});
    sim.Advance(0.1);
  }
  EXPECT_FALSE(sim.collided(r));
  // Before 3 s the same drive hits it.
  Simulation early(world, s.camera, {}, 1);
  early.AddRobot(s.teach_start, s.robot);
  for (int i = 0; i < 30 && !early.collided(0); ++i) {
    early.SetCommand(0, Twist2{0.5, 0.0});
    early.Advance(0.1);
  }
  EXPECT_TRUE(early.collided(0));
}

TEST(Simulation, TwoRobotsCollidingIsReported) {
  const Scenario s = LoadScenario("corridor_25m");
  Simulation sim(s.world, s.camera, {}, 1);
  sim.AddRobot(s.teach_start, s.robot);
  sim.AddRobot(s.teach_start * Pose2{1.0, 0.0, 0.0}, s.robot);
  for (int i = 0; i < 50; ++i) {
    sim.SetCommand(0, Twist2{0.5, 0.0});
    sim.Advance(0.1);
  }
  ASSERT_FALSE(sim.collisions().empty());
  EXPECT_EQ(sim.collisions().front().with, "robot 1");
}

}  // namespace
}  // namespace mapless::sim
