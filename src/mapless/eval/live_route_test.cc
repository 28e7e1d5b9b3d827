// The funnel-lane repeat on a route a leader is still teaching (issue 19): the robot drives the
// keyframes it has, stops at the last one (waiting for the leader) instead of ending the route,
// and drives on when the leader's next keyframes arrive, to the route's end.
#include <gtest/gtest.h>

#include "mapless/eval/teach_repeat.h"
#include "mapless/robot/loop.h"
#include "mapless/robot/methods.h"
#include "mapless/robot/sim_link.h"
#include "mapless/sim/scenario.h"

namespace mapless::eval {
namespace {

TEST(LiveRoute, TheRepeatWaitsAtTheLastKeyframeTaughtAndGoesOnWhenMoreArrive) {
  const sim::Scenario scenario = sim::LoadScenario("table1_almost_straight");
  const TaughtRoute taught = TeachOnSimulator(scenario, navigation::TeachOptions{});
  ASSERT_GE(taught.route->keyframes.size(), 6u);
  // What the leader has taught so far: the first 4 keyframes, not complete.
  auto partial = std::make_shared<route::Route>(*taught.route);
  partial->keyframes.resize(4);
  partial->complete = false;
  std::shared_ptr<const route::Route> served = partial;

  RepeatRunOptions run;
  const SimSetup setup = RepeatSimSetup(scenario, run);
  sim::Simulation sim(setup.world, setup.camera, {}, setup.seed);
  const int r = sim.AddRobot(setup.start, setup.robot);
  robot::SimLinkOptions link_options;
  link_options.period_s = 1.0 / scenario.camera.rate_hz;
  link_options.timeout_s = 300.0;
  robot::SimLink link(sim, r, link_options);
  navigation::RepeatOptions options;
  const double speed = RepeatSpeedFor(scenario, run.max_repeat_speed_mps);
  options.sloped.max_speed_mps = speed;
  robot::RepeatMethod method([&] { return served; }, options,
                             cv::Size(taught.route->image_width, taught.route->image_height));
  int waiting = 0;
  int moved_while_waiting = 0;
  int destination_while_waiting = -1;
  const robot::LoopResult result = robot::RunLoop(
      method, link, robot::LoopOptions{}, [&](const robot::Observation&, const robot::Decision& d) {
        if (d.reason.rfind("waiting for the leader", 0) == 0) {
          ++waiting;
          moved_while_waiting += d.command.v_mps != 0.0 || d.command.omega_radps != 0.0;
          if (const auto* repeat = d.DetailAs<robot::RepeatDetail>())
            destination_while_waiting = repeat->step.destination;
          // The leader gets further after the robot has waited 3 s.
          if (waiting == 30) served = taught.route;
        }
        return true;
      });
  EXPECT_EQ(waiting, 30);  // it waited until the rest arrived, and not after
  EXPECT_EQ(moved_while_waiting, 0);
  EXPECT_EQ(destination_while_waiting, 3);  // the last keyframe it had
  EXPECT_TRUE(result.finished) << result.reason;
  const double final_error = link.truth().DistanceTo(taught.path.back());
  EXPECT_LT(final_error, run.success_radius_m);
  EXPECT_FALSE(sim.collided(r));
}

}  // namespace
}  // namespace mapless::eval
