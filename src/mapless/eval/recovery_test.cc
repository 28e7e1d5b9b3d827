// Keyframe recovery (issue 21): when a keyframe's landmarks are gone, the repeat carries on with
// the following keyframe instead of stopping for good. "Gone" is made exact here: the keyframe's
// descriptors are replaced by random ones, so nothing the camera sees can match them.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <opencv2/core.hpp>

#include "mapless/eval/taught_once.h"
#include "mapless/eval/teach_repeat.h"
#include "mapless/sim/scenario.h"

namespace mapless::eval {
namespace {

TaughtRoute WithKeyframesGone(const TaughtRoute& taught, int first, int count = 1) {
  auto route = std::make_shared<route::Route>(*taught.route);
  cv::RNG rng(99);
  for (int k = first; k < first + count; ++k) {
    // A copy of its own: the route's copy shares the descriptors' pixels with `taught`.
    cv::Mat& d = route->keyframes[static_cast<std::size_t>(k)].descriptors;
    d = d.clone();
    rng.fill(d, cv::RNG::UNIFORM, 0, 256);
  }
  TaughtRoute out = taught;
  out.route = route;
  return out;
}

TEST(KeyframeRecovery, ARepeatSkipsAKeyframeWhoseLandmarksAreGone) {
  const auto& [scenario, taught] = TaughtOnce("table1_almost_straight");
  const int n = static_cast<int>(taught.route->keyframes.size());
  ASSERT_GE(n, 5);
  const int gone = n / 2;
  const TaughtRoute broken = WithKeyframesGone(taught, gone);

  RepeatRunOptions off;
  off.seed = 3;
  off.repeat.recovery_keyframes = 0;  // the paper: the robot stops at the keyframe, then aborts
  off.repeat.carry_on.max_distance_m = 0.0;
  const RepeatRun stuck = RepeatOnSimulator(scenario, broken, off);
  EXPECT_FALSE(stuck.completed) << stuck.status;
  EXPECT_NE(stuck.status.find("keyframe " + std::to_string(gone)), std::string::npos)
      << stuck.status;

  RepeatRunOptions on = off;
  on.repeat.recovery_keyframes = 3;
  const RepeatRun run = RepeatOnSimulator(scenario, broken, on);
  EXPECT_TRUE(run.success) << run.status << ", final error " << run.final_error_m;
  int recovered = 0;
  for (const auto& step : run.steps) {
    if (step.recovered_from < 0) continue;
    ++recovered;
    EXPECT_EQ(step.recovered_from, gone);
    EXPECT_EQ(step.destination, gone + 1);
    EXPECT_TRUE(step.switched);
  }
  EXPECT_EQ(recovered, 1);
}

// Three keyframes in a row gone, more than recovery reaches from where the robot stops: the
// repeat carries on along the taught odometry (the simulator's, with its noise) and the funnel
// lane takes over at the first keyframe that matches again.
TEST(KeyframeRecovery, ARepeatCarriesOnByOdometryThroughThreeKeyframesGone) {
  const auto& [scenario, taught] = TaughtOnce("table1_almost_straight");
  const int n = static_cast<int>(taught.route->keyframes.size());
  ASSERT_GE(n, 7);
  for (const auto& kf : taught.route->keyframes) ASSERT_TRUE(kf.odometry.has_value());
  const int gone = n / 2 - 1;
  const TaughtRoute broken = WithKeyframesGone(taught, gone, 3);
  RepeatRunOptions options;
  options.seed = 3;
  const RepeatRun run = RepeatOnSimulator(scenario, broken, options);
  EXPECT_TRUE(run.success) << run.status << ", final error " << run.final_error_m;
  int carrying = 0;
  int resumed_at = -1;
  Pose2 resumed_pose;
  for (std::size_t i = 0; i < run.steps.size(); ++i) {
    const auto& step = run.steps[i];
    if (step.carrying_on && step.destination == gone) {
      ++carrying;
      EXPECT_NE(step.command.v_mps, 0.0);
    } else if (carrying > 0 && resumed_at < 0) {
      resumed_at = step.destination;
      resumed_pose = run.path[i];
    }
  }
  EXPECT_GT(carrying, 5);
  EXPECT_GE(resumed_at, gone + 3);  // the funnel lane takes over after the three gone ones
  // ... and near where it should: heading for keyframe k puts the robot past k - 1, and a far
  // keyframe of this straight route that matches from afar must not end carrying on metres early
  // (RepeatOptions::carry_on_reach_factor; the route starts at the origin of the odometry).
  ASSERT_GT(resumed_at, 0);
  const Pose2 before = *taught.route->keyframes[static_cast<std::size_t>(resumed_at - 1)].odometry;
  EXPECT_LT(std::hypot(before.x_m - resumed_pose.x_m, before.y_m - resumed_pose.y_m), 1.5)
      << "resumed heading for keyframe " << resumed_at << " at x = " << resumed_pose.x_m
      << " m; keyframe " << resumed_at - 1 << " was taught at x = " << before.x_m << " m";
}

// Carrying on is driving without the route's view; it needs the watch to see the ground ahead
// (RepeatOptions::carry_on_unchecked_m). Here the watch is made blind (no check has enough
// points to count): carrying on gives up within 0.3 m of unchecked driving, and the robot stops.
TEST(KeyframeRecovery, CarryingOnGivesUpWhenTheWatchCannotSeeTheGround) {
  const auto& [scenario, taught] = TaughtOnce("table1_almost_straight");
  const int n = static_cast<int>(taught.route->keyframes.size());
  ASSERT_GE(n, 7);
  const int gone = n / 2 - 1;
  const TaughtRoute broken = WithKeyframesGone(taught, gone, 3);
  RepeatRunOptions options;
  options.seed = 3;
  options.repeat.obstacle.min_region_points = 1000000;
  options.repeat.obstacle.min_obstacle_points = 1000000;
  const RepeatRun run = RepeatOnSimulator(scenario, broken, options);
  EXPECT_FALSE(run.completed) << run.status;
  EXPECT_FALSE(run.collided);
  const double step_m = 0.2 * 0.1 * 1.2;  // one frame at the repeat's speed, with its noise
  int carrying = 0;
  for (const auto& step : run.steps) {
    if (!step.carrying_on) continue;
    ++carrying;
    EXPECT_LE(step.obstacle.unchecked_m, options.repeat.carry_on_unchecked_m + step_m);
  }
  EXPECT_LT(carrying, 20);  // it began, and gave up
}

// On an intact route the repeat passes the keyframes in order, one at a time: neither recovery
// nor carrying on steps in. (Until 2026-11-26 this test ran on a route that the test above had
// broken by accident, the descriptors being shared: it then allowed one recovery.)
TEST(KeyframeRecovery, AnIntactRouteIsRepeatedInOrder) {
  const auto& [scenario, taught] = TaughtOnce("table1_almost_straight");
  RepeatRunOptions options;
  options.seed = 3;
  const RepeatRun run = RepeatOnSimulator(scenario, taught, options);
  EXPECT_TRUE(run.success) << run.status;
  int last = 1;
  for (const auto& step : run.steps) {
    EXPECT_GE(step.destination, last);
    EXPECT_LE(step.destination, last + 1);
    EXPECT_LT(step.recovered_from, 0);
    EXPECT_FALSE(step.carrying_on);
    last = step.destination;
  }
}

}  // namespace
}  // namespace mapless::eval
