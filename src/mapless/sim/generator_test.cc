#include "mapless/sim/generator.h"

#include <gtest/gtest.h>

#include <cmath>

#include "mapless/core/check.h"
#include "mapless/core/testing.h"
#include "mapless/sim/scenario.h"

namespace mapless::sim {
namespace {

Scenario Generate(std::uint64_t seed, const std::string& kind = "") {
  GenerateOptions o;
  o.seed = seed;
  o.kind = kind;
  return ParseScenario(GenerateScenarioYaml(o), "generated", "");
}

// The taught path as points every few centimetres (teach start, then each go-to target).
std::vector<Eigen::Vector2d> DensePath(const Scenario& s) {
  std::vector<Eigen::Vector2d> out;
  Eigen::Vector2d at(s.teach_start.x_m, s.teach_start.y_m);
  for (const PathStep& step : s.teach_path) {
    if (step.kind != PathStep::Kind::kGoTo) continue;
    const int n = std::max(1, static_cast<int>((step.target - at).norm() / 0.05));
    for (int i = 0; i <= n; ++i)
      out.push_back(at + (step.target - at) * (static_cast<double>(i) / n));
    at = step.target;
  }
  return out;
}

TEST(Generator, TheSameSeedGivesTheSameTextAndAnotherSeedAnother) {
  GenerateOptions o;
  o.seed = 7;
  EXPECT_EQ(GenerateScenarioYaml(o), GenerateScenarioYaml(o));
  GenerateOptions other = o;
  other.seed = 8;
  EXPECT_NE(GenerateScenarioYaml(o), GenerateScenarioYaml(other));
}

TEST(Generator, EveryKindLoadsWithItsLabelsAndAPathOfSeveralMetres) {
  for (const std::string& kind : GeneratorKinds()) {
    for (std::uint64_t seed = 1; seed <= 5; ++seed) {
      const Scenario s = Generate(seed, kind);
      EXPECT_EQ(s.labels.at("kind"), kind);
      EXPECT_EQ(s.name, "gen_" + kind + "_" + std::to_string(seed));
      EXPECT_TRUE(s.labels.count("feasible") && s.labels.count("texture") &&
                  s.labels.count("obstacle_on_path") && s.labels.count("features"))
          << s.name;
      EXPECT_GE(s.PathLength(), 8.0) << s.name;
      EXPECT_TRUE(s.repeat_effects.has_value()) << s.name;
      ASSERT_EQ(s.destinations.size(), 1u) << s.name;
    }
  }
}

// Nothing of the world stands on the taught path or within a robot's radius and a margin of it;
// the object put there after the teach does, and only in the repeat's world.
TEST(Generator, TheTaughtPathIsClearAndTheAddedObjectStandsOnIt) {
  int with_object = 0;
  for (std::uint64_t seed = 1; seed <= 40; ++seed) {
    const Scenario s = Generate(seed);
    const std::vector<Eigen::Vector2d> path = DensePath(s);
    double clearance = 1e9;
    for (const Eigen::Vector2d& p : path)
      clearance = std::min(clearance, ClearanceTo(s.world, p.x(), p.y()));
    EXPECT_GE(clearance, s.robot.radius_m + 0.2) << s.name;
    const bool labelled = s.labels.at("obstacle_on_path") != "none";
    ASSERT_EQ(labelled, !s.repeat_variant.add.empty()) << s.name;
    if (!labelled) continue;
    ++with_object;
    const World repeat = ApplyVariant(s.world, s.repeat_variant);
    double on_path = 1e9;
    for (const Eigen::Vector2d& p : path)
      on_path = std::min(on_path, ClearanceTo(repeat, p.x(), p.y()));
    EXPECT_LE(on_path, 0.0) << s.name;
  }
  EXPECT_GT(with_object, 0);
}

TEST(Generator, TheStatedSharesHoldOverManySeedsAndWorldsWithoutTextureAreInfeasible) {
  GenerateOptions o;
  int obstacles = 0, infeasible = 0;
  const int n = 400;
  for (int seed = 1; seed <= n; ++seed) {
    o.seed = static_cast<std::uint64_t>(seed);
    const Scenario s = ParseScenario(GenerateScenarioYaml(o), "generated", "");
    obstacles += s.labels.at("obstacle_on_path") != "none" ? 1 : 0;
    const bool none = s.labels.at("texture") == "none";
    EXPECT_EQ(s.labels.at("feasible"), none ? "false" : "true") << s.name;
    if (none) {
      EXPECT_FALSE(s.labels.at("why").empty());
    }
    infeasible += none ? 1 : 0;
  }
  EXPECT_NEAR(static_cast<double>(obstacles) / n, o.obstacle_share, 0.06);
  EXPECT_NEAR(static_cast<double>(infeasible) / n, o.textureless_share, 0.03);
}

TEST(Generator, BadOptionsAreRefusedNamingTheField) {
  GenerateOptions o;
  o.kind = "moon";
  EXPECT_NE(testing::InputErrorOf([&] { GenerateScenarioYaml(o); }).find("GenerateOptions.kind"),
            std::string::npos);
  o.kind = "";
  o.obstacle_share = 1.5;
  EXPECT_NE(testing::InputErrorOf([&] { GenerateScenarioYaml(o); }).find("obstacle_share"),
            std::string::npos);
}

}  // namespace
}  // namespace mapless::sim
