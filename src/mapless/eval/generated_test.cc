// Issue 65: the follower on a route that keeps turning, and the generated worlds' runs.
#include "mapless/eval/generated.h"

#include <gtest/gtest.h>

#include "mapless/eval/eigenspace.h"
#include "mapless/sim/generator.h"

namespace mapless::eval {
namespace {

// The route of the regression: a lab with two S-curves, boxes beside them, a tiled floor. The
// follower of 13ff3d4 stopped in the first curve ("the ground ahead could not be checked") and
// never moved again.
TEST(GeneratedWorlds, TheFollowerArrivesOnTheLabsSRouteWithItsDefaultWatch) {
  const sim::Scenario lab = sim::LoadScenario("lab_s_route");
  for (std::uint64_t seed : {1, 2}) {
    EigenspaceRunOptions o;
    o.seed = seed;
    o.motion_noise = 0.1;
    ASSERT_TRUE(o.follower.obstacle.enabled);
    ASSERT_GT(o.follower.obstacle.max_unchecked_m, 0.0);
    const EigenspaceRun run = RunEigenspaceFollow(lab, o);
    EXPECT_TRUE(run.success) << "seed " << seed << ": " << run.status;
    EXPECT_FALSE(run.collided);
    EXPECT_EQ(run.obstacle_stops, 0) << "seed " << seed;
    EXPECT_LE(run.final_error_m, o.arrive_tolerance_m);
  }
}

// Each method on generated worlds: every run ends with an answer (arrived, or a stop that names
// its reason), and a world replayed from its file with its seed gives the same run.
TEST(GeneratedWorlds, EveryRunEndsWithAnAnswerAndAReplayGivesTheSameRun) {
  for (const std::string method : {"funnel", "eigenspace", "potential"}) {
    for (std::uint64_t seed : {3}) {
      sim::GenerateOptions g;
      g.seed = seed;
      const std::string text = sim::GenerateScenarioYaml(g);
      const sim::Scenario world = sim::ParseScenario(text, "generated", "");
      GeneratedRunOptions o;
      o.method = method;
      o.seed = seed;
      const GeneratedWorldResult a = RunGeneratedWorld(world, o);
      EXPECT_FALSE(a.no_answer) << method << " " << world.name << ": " << a.end_reason;
      EXPECT_FALSE(a.end_reason.empty());
      const GeneratedWorldResult b = RunGeneratedWorld(sim::ParseScenario(text, "again", ""), o);
      EXPECT_EQ(a.end_reason, b.end_reason) << method << " " << world.name;
      EXPECT_EQ(a.path.size(), b.path.size());
      EXPECT_EQ(a.stops.size(), b.stops.size());
      if (!a.path.empty() && a.path.size() == b.path.size()) {
        EXPECT_EQ(a.path.back().x_m, b.path.back().x_m);
        EXPECT_EQ(a.path.back().y_m, b.path.back().y_m);
      }
    }
  }
}

TEST(GeneratedWorlds, StopKindsTakeTheNumbersOut) {
  EXPECT_EQ(StopKind("obstacle ahead: 24% of the ground ahead does not move like the ground: "
                     "stopped"),
            "obstacle ahead: #% of the ground ahead does not move like the ground");
  EXPECT_EQ(StopKind("blocked for 30.00 s (x)"), "blocked for # s (x)");
}

}  // namespace
}  // namespace mapless::eval
