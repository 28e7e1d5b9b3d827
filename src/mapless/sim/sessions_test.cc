#include "mapless/sim/sessions.h"

#include <gtest/gtest.h>

#include <opencv2/core.hpp>
#include <set>

#include "mapless/core/check.h"
#include "mapless/sim/texture.h"

namespace mapless::sim {
namespace {

TEST(Sessions, SessionZeroIsTheTaughtWorldAndLaterOnesDriftFurther) {
  const Scenario s = LoadScenario("lifelong_outdoor");
  ASSERT_TRUE(s.sessions);
  const Scenario zero = SessionScenario(s, 0);
  EXPECT_EQ(zero.world.ground.changed, 0.0);
  EXPECT_EQ(zero.camera.effects.gain, s.camera.effects.gain);
  EXPECT_EQ(zero.camera.effects.bias, s.camera.effects.bias);
  EXPECT_TRUE(zero.repeat_variant.remove.empty());
  double last_share = 0.0;
  for (int session : {1, 5, 10, 20}) {
    const Scenario x = SessionScenario(s, session);
    EXPECT_NEAR(x.world.ground.changed, s.sessions->texture * session, 1e-12);
    for (const WorldObject& o : x.world.objects)
      EXPECT_EQ(o.texture.changed, x.world.ground.changed);
    EXPECT_GT(x.world.ground.changed, last_share);
    last_share = x.world.ground.changed;
    EXPECT_LT(x.camera.effects.gain, 1.0) << session;
    EXPECT_NE(*x.world.light_azimuth_deg, *SessionScenario(s, session - 1).world.light_azimuth_deg);
  }
  // Dusk: the brightness trend outweighs the swing by session 20.
  EXPECT_LT(SessionScenario(s, 20).camera.effects.bias,
            s.camera.effects.bias + s.sessions->light_swing);
}

TEST(Sessions, TheSameSessionIsTheSameWorld) {
  const Scenario s = LoadScenario("lifelong_car_park");
  for (int session : {0, 3, 17}) {
    EXPECT_EQ(DescribeSession(s, session), DescribeSession(s, session));
    EXPECT_EQ(SessionScenario(s, session).repeat_variant.remove,
              SessionScenario(s, session).repeat_variant.remove);
  }
  EXPECT_NE(DescribeSession(s, 3), DescribeSession(s, 4));
}

TEST(Sessions, ASourceNamesASessionAfterAnAt) {
  const Scenario s = LoadScenario("lifelong_car_park");
  const Scenario seven = LoadScenario("lifelong_car_park@7");
  const Scenario expected = SessionScenario(s, 7);
  EXPECT_EQ(seven.name, expected.name);
  EXPECT_EQ(seven.camera.effects.bias, expected.camera.effects.bias);
  EXPECT_EQ(seven.world.ground.changed, expected.world.ground.changed);
  EXPECT_EQ(seven.repeat_variant.remove, expected.repeat_variant.remove);
  EXPECT_EQ(LoadScenario("lifelong_car_park@0").world.ground.changed, 0.0);
  EXPECT_THROW(LoadScenario("table1_almost_straight@2"), InputError);  // no sessions: block
  EXPECT_THROW(LoadScenario("lifelong_car_park@123456"), InputError);
  EXPECT_THROW(LoadScenario("lifelong_car_park@x"), InputError);  // not a number: a name
}

TEST(Sessions, ParkedCarsComeAndGo) {
  const Scenario s = LoadScenario("lifelong_car_park");
  ASSERT_EQ(s.sessions->come_and_go.size(), 6u);
  std::set<std::string> ever_away;
  int away = 0;
  for (int session = 1; session <= 20; ++session) {
    const auto removed = SessionScenario(s, session).repeat_variant.remove;
    ever_away.insert(removed.begin(), removed.end());
    away += static_cast<int>(removed.size());
    EXPECT_NO_THROW(ApplyVariant(s.world, SessionScenario(s, session).repeat_variant));
  }
  EXPECT_EQ(ever_away.size(), 6u);  // every car is away on some session
  EXPECT_GT(away, 20) << "presence 0.5: about 60 of 120";
  EXPECT_LT(away, 100);
}

TEST(Sessions, AChangedTextureChangesThatShareAndGrowsFromTheSamePlaces) {
  TextureSpec spec;
  spec.size_px = 256;
  spec.seed = 9;
  const cv::Mat before = GenerateTextureImage(spec);
  // Texels that differ by more than 12 grey levels from the texture before, at a share.
  const auto differ = [&](double share) {
    spec.changed = share;
    cv::Mat diff;
    cv::absdiff(before, GenerateTextureImage(spec), diff);
    return cv::Mat(diff > 12);
  };
  // All changed: what differs where everything changed (two textures agree by chance elsewhere).
  const double full = cv::countNonZero(differ(1.0)) / static_cast<double>(before.total());
  EXPECT_GT(full, 0.5);
  cv::Mat previous_changed;
  for (double share : {0.2, 0.4, 0.8}) {
    const cv::Mat changed = differ(share);
    const double fraction = cv::countNonZero(changed) / static_cast<double>(changed.total());
    EXPECT_NEAR(fraction, share * full, 0.08) << share;
    if (!previous_changed.empty()) {
      // What had changed at the lower share is (nearly all) still changed.
      const cv::Mat kept = previous_changed & changed;
      EXPECT_GT(cv::countNonZero(kept), 0.9 * cv::countNonZero(previous_changed)) << share;
    }
    previous_changed = changed;
  }
}

TEST(Sessions, BadBlocksAreRefusedNamingTheField) {
  const std::string base = R"(
name: tiny
world:
  objects:
    - {type: box, tag: car, center: [3, 1], size_m: [1, 1, 1]}
teach:
  start: [0, 0, 0]
  path: [[2, 0]]
)";
  EXPECT_NO_THROW(ParseScenario(base + "sessions: {come_and_go: [car]}\n", "t.yaml", ""));
  const auto error = [&](const std::string& block) {
    try {
      ParseScenario(base + block, "t.yaml", "");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(error("sessions: {come_and_go: [bus]}\n").find("bus"), std::string::npos);
  EXPECT_NE(error("sessions: {texture: 2}\n").find("texture"), std::string::npos);
  EXPECT_NE(error("sessions: {presence: -1}\n").find("presence"), std::string::npos);
  EXPECT_NE(error("sessions: {colour: 1}\n").find("colour"), std::string::npos);
  EXPECT_THROW(SessionScenario(LoadScenario("table1_almost_straight"), 1), InputError);
}

}  // namespace
}  // namespace mapless::sim
