// Keyframe recovery (issue 21): when a keyframe's landmarks are gone, the repeat carries on with
// the following keyframe instead of stopping for good. "Gone" is made exact here: the keyframe's
// descriptors are replaced by random ones, so nothing the camera sees can match them.
#include <gtest/gtest.h>

#include <algorithm>
#include <opencv2/core.hpp>

#include "mapless/eval/teach_repeat.h"
#include "mapless/sim/scenario.h"

namespace mapless::eval {
namespace {

TaughtRoute WithKeyframeGone(const TaughtRoute& taught, int k) {
  auto route = std::make_shared<route::Route>(*taught.route);
  cv::Mat& d = route->keyframes[static_cast<std::size_t>(k)].descriptors;
  cv::RNG rng(99);
  rng.fill(d, cv::RNG::UNIFORM, 0, 256);
  TaughtRoute out = taught;
  out.route = route;
  return out;
}

class KeyframeRecovery : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    scenario_ = new sim::Scenario(sim::LoadScenario("table1_almost_straight"));
    taught_ = new TaughtRoute(TeachOnSimulator(*scenario_, navigation::TeachOptions{}));
  }
  static void TearDownTestSuite() {
    delete taught_;
    delete scenario_;
  }
  static const sim::Scenario* scenario_;
  static const TaughtRoute* taught_;
};
const sim::Scenario* KeyframeRecovery::scenario_ = nullptr;
const TaughtRoute* KeyframeRecovery::taught_ = nullptr;

TEST_F(KeyframeRecovery, ARepeatSkipsAKeyframeWhoseLandmarksAreGone) {
  const sim::Scenario& scenario = *scenario_;
  const TaughtRoute& taught = *taught_;
  const int n = static_cast<int>(taught.route->keyframes.size());
  ASSERT_GE(n, 5);
  const int gone = n / 2;
  const TaughtRoute broken = WithKeyframeGone(taught, gone);

  RepeatRunOptions off;
  off.seed = 3;
  off.repeat.recovery_keyframes = 0;  // the paper: the robot stops at the keyframe, then aborts
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

// On an intact route the repeat passes the keyframes in order; a recovery (a keyframe that stayed
// unmatched for recovery_after_s while the robot stood still, which happens on this route in some
// runs) skips exactly that one keyframe, and the run succeeds.
TEST_F(KeyframeRecovery, AnIntactRouteIsRepeatedInOrder) {
  for (const std::uint64_t seed : {3u}) {
    RepeatRunOptions options;
    options.seed = seed;
    options.repeat.recovery_keyframes = 3;
    const RepeatRun run = RepeatOnSimulator(*scenario_, *taught_, options);
    EXPECT_TRUE(run.success) << run.status;
    int last = 1;
    for (const auto& step : run.steps) {
      EXPECT_GE(step.destination, last);
      EXPECT_LE(step.destination, last + (step.recovered_from >= 0 ? 2 : 1));
      if (step.recovered_from >= 0) {
        EXPECT_EQ(step.recovered_from, last);
      }
      last = step.destination;
    }
  }
}

}  // namespace
}  // namespace mapless::eval
