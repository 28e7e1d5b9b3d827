#include "mapless/eval/eigenspace.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <string>

#include "mapless/core/check.h"
#include "mapless/sim/sessions.h"

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

// Issue 21: a box on the office route when the follower comes (gone after 40 s). The obstacle
// watch stops the follower before it and lets it go on; without the watch it drives into the box.
TEST(EigenspaceFollow, StopsBeforeABoxOnTheRouteAndGoesOnWhenItIsGone) {
  const sim::Scenario scenario = sim::LoadScenario("obstacle_box_office");
  EigenspaceRunOptions options = EigenspaceEntryOptions({"obstacle_box_office", "on-route"}, 1);
  const EigenspaceRun run = RunEigenspaceFollow(scenario, options);
  EXPECT_TRUE(run.success) << run.status;
  EXPECT_FALSE(run.collided);
  EXPECT_GE(run.stops_at_added_object, 1);
  EXPECT_GE(run.min_clearance_m, 0.2);
  options.follower.obstacle.enabled = false;  // the paper's follower
  const EigenspaceRun blind = RunEigenspaceFollow(scenario, options);
  EXPECT_TRUE(blind.collided) << blind.status;
  EXPECT_EQ(blind.obstacle_stops, 0);
}

// The route of lifelong_indoor ends 0.6 m before a box: near it the low-resolution view changes
// so fast with a lateral offset that the route images ahead stop matching, and the belief lagged
// one to seven images behind. The follower then either drove on into the box (seed 1) or waited
// before it until its time ran out (seed 3). With the belief kept from lagging further than the
// distance driven allows near the end (AppearanceFollowerOptions::anchor_end_m) and the arrival
// when the watch stops it there (arrive_blocked_within_images), it arrives.
TEST(EigenspaceFollow, ArrivesAtARouteThatEndsBeforeABoxInsteadOfDrivingIntoIt) {
  const sim::Scenario scenario = sim::SessionScenario(sim::LoadScenario("lifelong_indoor"), 2);
  for (const std::uint64_t seed : {1, 3}) {
    EigenspaceRunOptions options;
    options.seed = seed;
    const EigenspaceRun run = RunEigenspaceFollow(scenario, options);
    EXPECT_TRUE(run.success) << "seed " << seed << ": " << run.status;
    EXPECT_FALSE(run.collided) << "seed " << seed;
    EXPECT_LE(run.final_error_m, 0.5) << "seed " << seed;
  }
  EigenspaceRunOptions without;
  without.seed = 1;
  without.follower.anchor_end_m = 0.0;
  without.follower.arrive_blocked_within_images = -1;
  // ... and without what issue 65 added, with which the follower holds this route well enough
  // that it arrives even so: the leader's turning fed forward, the watch's creep.
  without.follower.leader_turn_feedforward = 0.0;
  without.follower.obstacle.creep_m = 0.0;
  // Without them it does not arrive. (Since issue 65's watch it touches the box past the end
  // here instead of stopping before it; before, the limit on unchecked ground stopped it.)
  const EigenspaceRun stopped = RunEigenspaceFollow(scenario, without);
  EXPECT_FALSE(stopped.success) << stopped.status;
}

// "Unchecked ground" in docs/appearance_route_following.md: on lifelong_indoor's session 19 the
// route taught on session 0 no longer fits; on 2026-12-02 the follower was lost there (seed 3),
// crept towards a tiled wall with the ground ahead unchecked and touched it, or, with the limit on
// unchecked ground, stopped before it. With the leader's turning fed forward (issue 65) it keeps to
// the route and arrives; the limit's stop is tested in ObstacleWatch.* and
// GeneratedWorlds.TheFollowerArrivesOnTheLabsSRouteWithItsDefaultWatch.
TEST(EigenspaceFollow, ArrivesOnAChangedSessionWhereItWasLostBefore) {
  const sim::Scenario world = sim::LoadScenario("lifelong_indoor");
  EigenspaceRunOptions options;
  const TaughtAppearance taught =
      TeachAppearanceOnSimulator(sim::SessionScenario(world, 0), options);
  options.taught = &taught;
  options.seed = 3;
  const EigenspaceRun run = RunEigenspaceFollow(sim::SessionScenario(world, 19), options);
  EXPECT_FALSE(run.collided) << run.status;
  EXPECT_TRUE(run.success) << run.status;
  options.follower.leader_turn_feedforward = 0.0;  // before
  const EigenspaceRun before = RunEigenspaceFollow(sim::SessionScenario(world, 19), options);
  EXPECT_FALSE(before.success) << before.status;
}

// Issue 21, recovery: carts along both walls filled the leader's view from 5 m to 12 m and are
// gone when the follower comes. The follower carries on along the leader's odometry where no
// route image fits and completes the route (without recovery it does not:
// `mapless eval eigenspace --only route_images_gone_office`, README).
TEST(EigenspaceFollow, CarriesOnWhereTheRouteImagesNoLongerFitAndArrives) {
  const sim::Scenario scenario = sim::LoadScenario("route_images_gone_office");
  const EigenspaceRunOptions options =
      EigenspaceEntryOptions({"route_images_gone_office", "on-route"}, 1);
  int carrying = 0;
  double carried_from_m = 1e9;
  double carried_to_m = -1e9;
  const EigenspaceRun run = RunEigenspaceFollow(
      scenario, options, [&](const navigation::FollowerStep& step, const Pose2& truth) {
        if (!step.carrying_on) return;
        ++carrying;
        EXPECT_EQ(step.state, navigation::FollowerState::kFollowing);
        EXPECT_NE(step.reason.find("carrying on"), std::string::npos) << step.reason;
        carried_from_m = std::min(carried_from_m, truth.x_m);
        carried_to_m = std::max(carried_to_m, truth.x_m);
      });
  EXPECT_TRUE(run.success) << run.status;
  EXPECT_FALSE(run.collided);
  EXPECT_LT(run.final_error_m, 0.6);
  EXPECT_GE(carrying, 10);
  // Where the carts were in view (they stood from 8 m to 12 m).
  EXPECT_GT(carried_from_m, 2.0);
  EXPECT_LT(carried_to_m, 12.0);
  EXPECT_THROW(EigenspaceEntryOptions({"route_images_gone_office", "sideways"}, 1), InputError);
}

TEST(EigenspaceSuite, HasTwoRoutesAndSixExperimentsEachAndTheFollowersObstacle) {
  const auto entries = EigenspaceSuiteEntries();
  EXPECT_EQ(entries.size(), 15U);
  EXPECT_THROW(EigenspaceEntryOptions({"office_aliasing", "sideways"}, 1), InputError);
}

}  // namespace
}  // namespace mapless::eval
