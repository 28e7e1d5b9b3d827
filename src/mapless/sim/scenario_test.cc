#include "mapless/sim/scenario.h"

#include <gtest/gtest.h>

#include "mapless/core/check.h"
#include "mapless/core/testing.h"

namespace mapless::sim {
namespace {

const char* kMinimal = R"(
name: tiny
world:
  objects:
    - {type: box, tag: car, center: [3, 1], size_m: [1, 1, 1]}
teach:
  start: [0, 0, 0]
  path: [[2, 0]]
)";

TEST(Scenario, EveryBuiltinScenarioLoadsAndValidates) {
  const auto names = BuiltinScenarioNames();
  EXPECT_GE(names.size(), 15u);
  for (const auto& name : names) {
    Scenario s;
    ASSERT_NO_THROW(s = LoadScenario(name)) << name;
    EXPECT_EQ(s.name, name);
    EXPECT_FALSE(s.description.empty()) << name;
    EXPECT_GT(s.PathLength(), 0.0) << name;
    EXPECT_NO_THROW(ApplyVariant(s.world, s.repeat_variant)) << name;
  }
}

TEST(Scenario, PaperScenariosHaveThePapersPathLengths) {
  struct Expect {
    const char* name;
    double length_m;
  };
  // Kassir et al. Section VII: 9 m, 6 m, 25 m, 10 m, 10 m, 30 m, 70 m.
  for (const Expect& e :
       {Expect{"narrow_room_sharp_turn", 9}, Expect{"wide_left_turn_offset_start", 6},
        Expect{"corridor_25m", 25}, Expect{"table1_sharp_turn_low_texture", 10},
        Expect{"table1_almost_straight", 10}, Expect{"indoor_30m", 30},
        Expect{"outdoor_70m", 70}}) {
    const Scenario s = LoadScenario(e.name);
    EXPECT_NEAR(s.PathLength(), e.length_m, 0.1 * e.length_m) << e.name;
  }
}

TEST(Scenario, OffsetStartRepeatBeginsTwoMetresAheadOfTheTaughtStart) {
  const Scenario s = LoadScenario("wide_left_turn_offset_start");
  EXPECT_NEAR(s.teach_start.DistanceTo(s.repeat_start), 2.0, 0.05);
}

TEST(Scenario, LoopWithRemovedCarsLosesTwoCarsInTheRepeat) {
  const Scenario s = LoadScenario("outdoor_loop_cars_removed");
  EXPECT_EQ(s.repeat_variant.remove.size(), 2u);
  EXPECT_LT(ApplyVariant(s.world, s.repeat_variant).objects.size(), s.world.objects.size());
}

TEST(Scenario, RotationInPlaceScenarioRotatesNinetyDegrees) {
  const Scenario s = LoadScenario("rotation_in_place");
  double rotation = 0;
  for (const auto& step : s.teach_path) {
    if (step.kind == PathStep::Kind::kRotate) rotation += step.rotate_rad;
  }
  EXPECT_NEAR(std::abs(rotation), kPi / 2, 1e-9);
}

TEST(Scenario, MinimalScenarioUsesDefaults) {
  const Scenario s = ParseScenario(kMinimal, "tiny.yaml", "");
  EXPECT_EQ(s.camera.model.width, 320);
  EXPECT_EQ(s.camera.model.height, 240);
  EXPECT_NEAR(s.camera.model.fx, 160.0 / std::tan(DegToRad(30)), 1e-9);
  EXPECT_DOUBLE_EQ(s.camera.rate_hz, 10.0);
  EXPECT_EQ(s.world.objects.size(), 1u);
}

TEST(Scenario, MalformedFieldIsReportedWithFileLineAndField) {
  std::string text = kMinimal;
  text.replace(text.find("size_m: [1, 1, 1]"), 17, "size_m: [1, one, 1]");
  const std::string err = testing::InputErrorOf([&] { ParseScenario(text, "bad.yaml", ""); });
  EXPECT_NE(err.find("bad.yaml:5:"), std::string::npos) << err;
  EXPECT_NE(err.find("world.objects[0].size_m"), std::string::npos) << err;
}

TEST(Scenario, UnknownFieldAndUnknownTagAreErrors) {
  std::string text = std::string(kMinimal) + "repeat:\n  variant: {remove: [truck]}\n";
  EXPECT_NE(testing::InputErrorOf([&] {
              ParseScenario(text, "t.yaml", "");
            }).find("no object has tag 'truck'"),
            std::string::npos);
  std::string typo = std::string(kMinimal) + "camra: {width: 10}\n";
  EXPECT_NE(testing::InputErrorOf([&] {
              ParseScenario(typo, "t.yaml", "");
            }).find("camra: unknown field"),
            std::string::npos);
}

// At repeat time a box is new on the path and the parked car drives off after 5 s.
TEST(Scenario, VariantsAddObjectsAndTimeTheirLeaving) {
  const std::string text = std::string(kMinimal) +
                           "repeat:\n  variant:\n    add:\n      - {type: box, tag: parcel, "
                           "center: [1, 0], size_m: [0.4, 0.4, 0.4]}\n    leave_s: {car: 5}\n";
  const Scenario s = ParseScenario(text, "t.yaml", "");
  const World repeat = ApplyVariant(s.world, s.repeat_variant);
  ASSERT_EQ(repeat.objects.size(), 2u);
  EXPECT_EQ(repeat.objects[1].tag, "parcel");
  EXPECT_EQ(repeat.objects[0].leaves_s, 5.0);
  EXPECT_EQ(WorldAt(repeat, 4.9).objects.size(), 2u);
  ASSERT_EQ(WorldAt(repeat, 5.0).objects.size(), 1u);
  EXPECT_EQ(WorldAt(repeat, 5.0).objects[0].tag, "parcel");
  EXPECT_EQ(ChangeTimes(repeat), std::vector<double>{5.0});
  // The teach world is untouched.
  EXPECT_EQ(s.world.objects.size(), 1u);
  EXPECT_FALSE(s.world.objects[0].timed());
  // An object's own times; errors name the field.
  const std::string timed = std::string(kMinimal) +
                            "repeat:\n  variant:\n    add:\n      - {type: cylinder, center: [1, "
                            "0], radius_m: 0.2, appears_s: 2, leaves_s: 9}\n";
  const World w = ApplyVariant(ParseScenario(timed, "t.yaml", "").world,
                               ParseScenario(timed, "t.yaml", "").repeat_variant);
  EXPECT_EQ(ChangeTimes(w), (std::vector<double>{2.0, 9.0}));
  EXPECT_EQ(WorldAt(w, 1.0).objects.size(), 1u);
  EXPECT_EQ(WorldAt(w, 3.0).objects.size(), 2u);
  const std::string backwards = std::string(kMinimal) +
                                "repeat:\n  variant:\n    add:\n      - {type: cylinder, center: "
                                "[1, 0], radius_m: 0.2, appears_s: 4, leaves_s: 3}\n";
  EXPECT_NE(testing::InputErrorOf([&] { ParseScenario(backwards, "t.yaml", ""); }).find("leaves_s"),
            std::string::npos);
  const std::string unknown =
      std::string(kMinimal) + "repeat:\n  variant:\n    leave_s: {truck: 3}\n";
  EXPECT_NE(testing::InputErrorOf([&] {
              ParseScenario(unknown, "t.yaml", "");
            }).find("no object has tag 'truck'"),
            std::string::npos);
}

// The limits of docs/hardening.md, each named in its error; the built-in scenarios are far inside.
TEST(Scenario, ValuesThatWouldHangOrExhaustTheSimulatorAreRefusedByName) {
  const auto error_of = [](const std::string& from, const std::string& to) {
    std::string text = kMinimal;
    const std::size_t at = text.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    text.replace(at, from.size(), to);
    return testing::InputErrorOf([&] { ParseScenario(text, "s.yaml", ""); });
  };
  EXPECT_NE(error_of("size_m: [1, 1, 1]", "size_m: [1e9, 1, 1]").find("(box).size"),
            std::string::npos);
  EXPECT_NE(error_of("center: [3, 1]", "center: [3e5, 1]").find("beyond 10000 m"),
            std::string::npos);
  EXPECT_NE(error_of("size_m: [1, 1, 1]}",
                     "size_m: [0.1, 0.1, 1], repeat: {count: 1000, "
                     "step: [0.2, 0]}}\n    - {type: box, center: [3, 5], "
                     "size_m: [0.1, 0.1, 1], repeat: {count: 1000, step: "
                     "[0.2, 0]}}\n    - {type: box, center: [3, 9], "
                     "size_m: [0.1, 0.1, 1]}")
                .find("more than 2000 objects"),
            std::string::npos);
  EXPECT_NE(error_of("path: [[2, 0]]", "speed_mps: 1e-300\n  path: [[2, 0]]").find("speed_mps"),
            std::string::npos);
  EXPECT_NE(error_of("path: [[2, 0]]", "path: [[2, 0], {rotate_deg: 1e300}]").find("rotation"),
            std::string::npos);
  EXPECT_NE(error_of("name: tiny", "name: tiny\ncamera: {rate_hz: 1e-300}").find("rate_hz"),
            std::string::npos);
  EXPECT_NE(error_of("size_m: [1, 1, 1]}",
                     "size_m: [1, 1, 1], texture: {size_px: 2048}, repeat: "
                     "{count: 40, step: [2, 0]}}")
                .find("distinct textures"),
            std::string::npos);
  for (const auto& name : BuiltinScenarioNames()) EXPECT_NO_THROW(LoadScenario(name)) << name;
}

TEST(Scenario, UnknownBuiltinNameSaysSo) {
  EXPECT_NE(testing::InputErrorOf([] {
              LoadScenario("no_such_scenario");
            }).find("unknown scenario 'no_such_scenario'"),
            std::string::npos);
}

TEST(Scenario, RepeatCopiesObjectsAlongAStep) {
  const char* rep = R"(
world:
  objects:
    - {type: poster, center: [1, 2, 1.5], size_m: [0.5, 0.7], repeat: {count: 4, step: [2.5, 0]}}
    - {type: poster, center: [1, -2, 1.5], size_m: [0.5, 0.7], texture: {type: poster, seed: 9},
       repeat: {count: 3, step: [2.5, 0]}}
teach: {start: [0, 0, 0], path: [[1, 0]]}
)";
  const Scenario s = ParseScenario(rep, "rep.yaml", "");
  ASSERT_EQ(s.world.objects.size(), 7u);
  EXPECT_DOUBLE_EQ(s.world.objects[3].center.x(), 8.5);
  // Copies differ unless the seed is explicit; with an explicit seed they are identical (aliasing).
  EXPECT_NE(s.world.objects[0].texture.seed, s.world.objects[3].texture.seed);
  EXPECT_EQ(s.world.objects[4].texture.seed, s.world.objects[6].texture.seed);
}

}  // namespace
}  // namespace mapless::sim
