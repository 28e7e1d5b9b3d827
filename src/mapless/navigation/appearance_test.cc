#include "mapless/navigation/appearance.h"

#include <gtest/gtest.h>

#include <atomic>
#include <opencv2/imgproc.hpp>
#include <thread>

#include "mapless/core/check.h"
#include "mapless/sim/simulation.h"

namespace mapless::navigation {
namespace {

// A smooth random image: a stand-in for a camera frame when only the bookkeeping is tested.
cv::Mat SmoothImage(int seed) {
  cv::Mat image(240, 320, CV_8UC1);
  cv::RNG rng(static_cast<std::uint64_t>(seed));
  rng.fill(image, cv::RNG::UNIFORM, 0, 255);
  cv::GaussianBlur(image, image, cv::Size(0, 0), 6.0);
  return image;
}

TEST(AppearanceLeader, StoresAnImageEverySpacingAndPublishesConsistentSnapshots) {
  AppearanceLeader leader;
  int stored = 0;
  for (int i = 0; i < 50; ++i) {
    // 5 cm per frame: a route image every 4 frames (0.2 m).
    stored += leader.Update(SmoothImage(i), Pose2{0.05 * i, 0.0, 0.0});
  }
  EXPECT_EQ(stored, 13);
  const auto route = leader.Snapshot();
  ASSERT_TRUE(route);
  EXPECT_EQ(route->size(), 13);
  EXPECT_EQ(route->space.images(), 13);
  EXPECT_FALSE(route->complete);
  EXPECT_NEAR(route->SpacingM(), 0.2, 1e-9);
  leader.Finish();
  EXPECT_TRUE(leader.Snapshot()->complete);
  EXPECT_THROW(leader.Update(SmoothImage(99), Pose2{}), InputError);
}

TEST(AppearanceLeader, BatchPcaHasNoRouteBeforeItIsFinished) {
  AppearanceLeaderOptions options;
  options.incremental = false;
  AppearanceLeader leader(options);
  for (int i = 0; i < 20; ++i) leader.Update(SmoothImage(i), Pose2{0.05 * i, 0.0, 0.0});
  EXPECT_EQ(leader.Snapshot(), nullptr);
  leader.Finish();
  ASSERT_TRUE(leader.Snapshot());
  EXPECT_EQ(leader.Snapshot()->space.images(), leader.images());
}

// The leader adds images in one thread while a follower thread reads snapshots: every snapshot a
// reader gets is whole (as many projections as images, a basis matching the mean), never a model
// half-way through an update.
TEST(AppearanceRouteChannel, ReadersNeverSeeAHalfUpdatedModel) {
  route::AppearanceRouteChannel channel;
  std::atomic<bool> done{false};
  std::atomic<int> checked{0};
  std::atomic<int> broken{0};
  std::thread reader([&] {
    int last_size = 0;
    while (!done.load()) {
      const auto route = channel.Latest();
      if (!route) continue;
      const bool whole = route->space.images() == route->size() &&
                         route->space.basis.rows() == route->space.mean.size() &&
                         route->space.basis.cols() == route->space.projections.rows() &&
                         route->size() >= last_size;
      broken += !whole;
      last_size = route->size();
      ++checked;
    }
  });
  AppearanceLeader leader;
  for (int i = 0; i < 120; ++i) {
    if (leader.Update(SmoothImage(i), Pose2{0.2 * i, 0.0, 0.0})) channel.Publish(leader.Snapshot());
  }
  done = true;
  reader.join();
  EXPECT_GT(checked.load(), 0);
  EXPECT_EQ(broken.load(), 0);
  EXPECT_EQ(channel.Latest()->size(), 120);
}

std::shared_ptr<const route::AppearanceRoute> OfficeRoute() {
  static const auto route = [] {
    AppearanceLeader leader;
    sim::DriveTaughtPath(sim::LoadScenario("office_aliasing"), sim::DriveOptions{},
                         [&](const sim::DriveFrame& f) { leader.Update(f.image, f.odometry); });
    leader.Finish();
    return leader.Snapshot();
  }();
  return route;
}

TEST(AppearanceFollower, WaitsWhileTheRouteHasFewerThanTwoImages) {
  AppearanceLeader leader;
  leader.Update(SmoothImage(1), Pose2{});
  AppearanceFollower follower;
  const FollowerStep step = follower.Update(SmoothImage(2), Pose2{}, *leader.Snapshot(), 0);
  EXPECT_EQ(step.state, FollowerState::kWaitingForLeader);
  EXPECT_EQ(step.command.v_mps, 0.0);
  EXPECT_FALSE(step.reason.empty());
}

TEST(AppearanceFollower, LocalizesWithSmallTurnsThenStopsOnABlackCameraAndSaysWhy) {
  const auto route = OfficeRoute();
  const sim::Scenario scenario = sim::LoadScenario("office_aliasing");
  sim::Simulation sim(scenario.world, scenario.camera, {}, 3);
  const int robot = sim.AddRobot(scenario.teach_start, scenario.robot);
  AppearanceFollower follower;
  FollowerStep step;
  bool turned_left = false;
  bool turned_right = false;
  for (int i = 0; i < 200 && step.state == FollowerState::kInitializing; ++i) {
    step = follower.Update(sim.Render(robot), sim.robot(robot).odometry(), *route, sim.now_ns());
    turned_left |= step.command.omega_radps > 0.0;
    turned_right |= step.command.omega_radps < 0.0;
    sim.SetCommand(robot, step.command);
    sim.Advance(0.1);
  }
  EXPECT_TRUE(turned_left && turned_right);
  step = follower.Update(sim.Render(robot), sim.robot(robot).odometry(), *route, sim.now_ns());
  ASSERT_EQ(step.state, FollowerState::kFollowing) << step.reason;
  EXPECT_LE(step.index, 3);
  EXPECT_GT(step.command.v_mps, 0.0);
  // The camera goes black: the robot stops within this control period and says why.
  const cv::Mat black = cv::Mat::zeros(240, 320, CV_8UC1);
  step = follower.Update(black, sim.robot(robot).odometry(), *route, sim.now_ns());
  EXPECT_EQ(step.state, FollowerState::kStopped);
  EXPECT_EQ(step.command.v_mps, 0.0);
  EXPECT_EQ(step.command.omega_radps, 0.0);
  EXPECT_NE(step.reason.find("camera fault: black frame"), std::string::npos) << step.reason;
  // Images return: it follows again.
  step = follower.Update(sim.Render(robot), sim.robot(robot).odometry(), *route, sim.now_ns());
  EXPECT_EQ(step.state, FollowerState::kFollowing) << step.reason;
}

}  // namespace
}  // namespace mapless::navigation
