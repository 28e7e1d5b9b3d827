#include "mapless/eval/eigenspace.h"

#include <gtest/gtest.h>

#include "mapless/core/check.h"

namespace mapless::eval {
namespace {

// The aliasing office route (identical doors and notices every 3 m), follower starting on the
// route: it arrives, stays on the route, and Markov localization keeps the index within one image
// where the nearest projection alone is fooled by the repeated places.
TEST(EigenspaceFollow, OfficeRouteMarkovLocalizationBeatsNearestProjection) {
  const sim::Scenario scenario = sim::LoadScenario("office_aliasing");
  const EigenspaceRun run =
      RunEigenspaceFollow(scenario, EigenspaceEntryOptions({"office_aliasing", "on-route"}, 1));
  EXPECT_TRUE(run.success) << run.status;
  EXPECT_FALSE(run.collided);
  EXPECT_GT(run.frames_after_convergence, 300);
  EXPECT_LE(run.lateral_rms_m, 0.3);
  EXPECT_GE(run.localization_within_one, 0.95);
  EXPECT_GT(run.localization_within_one, run.nearest_within_one + 0.1);
}

// Leader and follower in one world: the follower starts after the leader's fifth image and
// follows the route while it is being taught, waiting at its end when it catches up.
TEST(EigenspaceFollow, FollowsWhileTheLeaderIsStillTeaching) {
  const sim::Scenario scenario = sim::LoadScenario("office_aliasing");
  const EigenspaceRun run =
      RunEigenspaceFollow(scenario, EigenspaceEntryOptions({"office_aliasing", "concurrent"}, 1));
  EXPECT_TRUE(run.success) << run.status;
  EXPECT_FALSE(run.collided);
  EXPECT_GT(run.route_images, 100);
  EXPECT_LE(run.lateral_rms_m, 0.3);
}

TEST(EigenspaceFollow, RejectsBatchPcaWhileTheLeaderTeaches) {
  EigenspaceRunOptions options;
  options.concurrent = true;
  options.leader.incremental = false;
  EXPECT_THROW(RunEigenspaceFollow(sim::LoadScenario("office_aliasing"), options), InputError);
}

TEST(EigenspaceSuite, HasTwoRoutesAndSixExperimentsEach) {
  const auto entries = EigenspaceSuiteEntries();
  EXPECT_EQ(entries.size(), 12U);
  EXPECT_THROW(EigenspaceEntryOptions({"office_aliasing", "sideways"}, 1), InputError);
}

}  // namespace
}  // namespace mapless::eval
