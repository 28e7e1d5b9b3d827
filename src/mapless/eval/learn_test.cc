// Learning experiences in closed loop (issue 45): a repeat through a place whose appearance
// changed learns views of the keyframes there; the route with them is repeated again, steering by
// the learned views where they match best.
#include <gtest/gtest.h>

#include "mapless/eval/lifelong.h"
#include "mapless/eval/taught_once.h"
#include "mapless/eval/teach_repeat.h"
#include "mapless/navigation/experiences.h"
#include "mapless/sim/sessions.h"

namespace mapless::eval {
namespace {

TEST(Experiences, ARepeatWhereThePlaceChangedLearnsViewsAndTheNextRepeatSteersByThem) {
  const auto& [scenario, taught] = TaughtOnce("keyframe_car_gone");
  RepeatRunOptions options;
  options.seed = 2;
  options.repeat.learn = true;
  const RepeatRun first = RepeatOnSimulator(scenario, taught, options);
  ASSERT_TRUE(first.success) << first.status;
  std::vector<navigation::LearnedView> learned;
  int learned_steps = 0;
  for (const auto& step : first.steps) {
    if (step.learned < 0) continue;
    ++learned_steps;
    EXPECT_NE(step.learned_why.find("looks different"), std::string::npos) << step.learned_why;
  }
  std::printf("first repeat: %d views learned\n", learned_steps);
  ASSERT_GT(learned_steps, 0);
  ASSERT_EQ(first.learned.size(), static_cast<std::size_t>(learned_steps));

  // The visit applied to a copy of the route: the views stand under their keyframes.
  auto route = std::make_shared<route::Route>(*taught.route);
  const int added = navigation::ApplyVisit(route.get(), first.used_views, first.learned,
                                           options.repeat.experiences);
  EXPECT_EQ(added, learned_steps);
  EXPECT_EQ(route->visits, 1);
  const int k = first.learned.front().keyframe;
  ASSERT_EQ(route->keyframes[static_cast<std::size_t>(k)].views.size(), 1u);
  EXPECT_EQ(route->keyframes[static_cast<std::size_t>(k)].views[0].learned_at, 1);

  // The same changed place again, with the learned views: the repeat completes, steering by a
  // learned view at the keyframe it learned, and finds more matches there than the taught view.
  TaughtRoute learned_route = taught;
  learned_route.route = route;
  options.repeat.learn = false;
  const RepeatRun second = RepeatOnSimulator(scenario, learned_route, options);
  EXPECT_TRUE(second.success) << second.status;
  bool steered_by_learned = false;
  for (const auto& step : second.steps)
    steered_by_learned |= step.destination == k && step.view > 0;
  EXPECT_TRUE(steered_by_learned) << "keyframe " << k;
  ASSERT_GT(second.used_views.size(), static_cast<std::size_t>(k));
  EXPECT_EQ(second.used_views[static_cast<std::size_t>(k)], 1);
}

// The changing world's sessions in order (eval lifelong, shortened): with the drift of ten
// sessions a step, each repeat completes and the route grows by the views it learned.
TEST(Lifelong, ARouteRepeatedOnSessionsOfAChangingWorldLearnsViewsAndCompletesEach) {
  sim::Scenario scenario = sim::LoadScenario("lifelong_indoor");
  sim::WorldChange& change = *scenario.sessions;
  change.brightness *= 10;
  change.contrast *= 10;
  change.light_turn_deg *= 10;
  change.texture *= 10;
  const TaughtRoute taught =
      TeachOnSimulator(sim::SessionScenario(scenario, 0), navigation::TeachOptions{});
  LifelongOptions options;
  options.sessions = 2;
  const LifelongRun run = RunLifelong(scenario, taught, options);
  ASSERT_EQ(run.sessions.size(), 2u);
  const int taught_views = static_cast<int>(taught.route->keyframes.size());
  int last_views = taught_views;
  for (const LifelongSession& s : run.sessions) {
    std::printf("%s: %s, %d learned, %d views\n", sim::DescribeSession(scenario, s.session).c_str(),
                s.status.c_str(), s.learned, s.route_views);
    EXPECT_TRUE(s.success) << s.status;
    EXPECT_EQ(s.route_views, last_views + s.learned) << "session " << s.session;
    last_views = s.route_views;
  }
  EXPECT_GT(run.route_views, taught_views);
  EXPECT_TRUE(run.all_succeeded());
}

// The appearance follower on the outdoor changing world's sessions (eval lifelong --method
// eigenspace, shortened): each follow arrives and learns views of places that look different,
// and the route grows by them; without learning it keeps its taught images.
TEST(Lifelong, AFollowerOnSessionsOfAChangingWorldLearnsViewsAndArrives) {
  const sim::Scenario scenario = sim::LoadScenario("lifelong_outdoor");
  const TaughtAppearance taught =
      TeachAppearanceOnSimulator(sim::SessionScenario(scenario, 0), EigenspaceRunOptions{});
  const int images = static_cast<int>(taught.stored.images.size());
  LifelongOptions options;
  options.sessions = 3;
  const LifelongRun run = RunLifelongFollow(scenario, taught, options);
  ASSERT_EQ(run.sessions.size(), 3u);
  int last = images;
  for (const LifelongSession& s : run.sessions) {
    std::printf("%s: %s, %d learned, %d images and views\n",
                sim::DescribeSession(scenario, s.session).c_str(), s.status.c_str(), s.learned,
                s.route_views);
    EXPECT_TRUE(s.success) << s.status;
    EXPECT_EQ(s.route_views, last + s.learned) << "session " << s.session;
    last = s.route_views;
  }
  EXPECT_GT(run.route_views, images);
  LifelongOptions single = options;
  single.learn = false;
  const LifelongRun alone = RunLifelongFollow(scenario, taught, single);
  EXPECT_EQ(alone.route_views, images);
}

}  // namespace
}  // namespace mapless::eval
