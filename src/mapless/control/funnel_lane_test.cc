#include "mapless/control/funnel_lane.h"

#include <gtest/gtest.h>

#include "mapless/core/check.h"

namespace mapless::control {
namespace {

// Destination features spread over the image, left and right.
const std::vector<double> kDest = {-140, -90, -60, -25, 30, 55, 95, 150};

std::vector<FeaturePair> Map(const std::vector<double>& dest, double scale, double offset) {
  std::vector<FeaturePair> out;
  for (double uj : dest) out.push_back({scale * uj + offset, uj});
  return out;
}

TEST(StandardFunnelLane, OnThePathBeforeTheKeyframeGoesStraight) {
  // Approaching the keyframe head-on: every feature is closer to the centre than it will be.
  const auto r = ComputeStandardFunnelLane(Map(kDest, 0.8, 0.0), {});
  EXPECT_EQ(r.command, TurnCommand::kStraight);
  EXPECT_EQ(r.inside, static_cast<int>(kDest.size()));
  EXPECT_GT(r.twist.v_mps, 0.0);
  EXPECT_EQ(r.twist.omega_radps, 0.0);
}

TEST(StandardFunnelLane, SceneShiftedLeftMeansTurnLeftWithTheFixedRate) {
  // The robot is turned right of the keyframe heading: features appear shifted left.
  StandardFunnelLaneOptions o;
  const auto r = ComputeStandardFunnelLane(Map(kDest, 0.9, -60.0), o);
  EXPECT_EQ(r.command, TurnCommand::kLeft);
  EXPECT_GT(r.left_votes, r.right_votes);
  EXPECT_DOUBLE_EQ(r.twist.omega_radps, o.turn_rate_radps);
  EXPECT_DOUBLE_EQ(r.twist.v_mps, o.forward_speed_mps);
}

TEST(StandardFunnelLane, SceneShiftedRightMeansTurnRight) {
  const auto r = ComputeStandardFunnelLane(Map(kDest, 0.9, 60.0), {});
  EXPECT_EQ(r.command, TurnCommand::kRight);
  EXPECT_LT(r.twist.omega_radps, 0.0);
}

// Fig. 5 of the paper: features only on the right, destination features right of the current
// ones. (a) from a left turn (pure rotation: same spread), (b) from moving forward (spread grows).
const std::vector<double> kRightOnly = {60, 80, 110, 130, 150};

TEST(StandardFunnelLane, CannotTellFig5RotationFromTranslation) {
  const auto rotation = ComputeStandardFunnelLane(Map(kRightOnly, 1.0, -25.0), {});
  const auto translation = ComputeStandardFunnelLane(Map(kRightOnly, 0.8, 0.0), {});
  EXPECT_EQ(rotation.command, TurnCommand::kStraight);  // the ambiguity of Section IV-B
  EXPECT_EQ(translation.command, TurnCommand::kStraight);
}

TEST(SlopedFunnelLane, Fig5RotationTurnsSharplyAndTranslationNearlyStraight) {
  const auto rotation = ComputeSlopedFunnelLane(Map(kRightOnly, 1.0, -25.0), {});
  const auto translation = ComputeSlopedFunnelLane(Map(kRightOnly, 0.8, 0.0), {});
  ASSERT_TRUE(rotation.ok);
  ASSERT_TRUE(translation.ok);
  EXPECT_EQ(rotation.right_features, 5);
  EXPECT_EQ(rotation.left_features, 0);
  EXPECT_EQ(rotation.command, TurnCommand::kLeft);
  EXPECT_EQ(translation.command, TurnCommand::kLeft);
  // Same sign of slope x, but the rotation has slope y ~ 0: a much sharper turn.
  EXPECT_NEAR(rotation.slope_y, 0.0, 1e-9);
  EXPECT_NEAR(translation.slope_y, 0.2, 1e-9);
  const double radius_rotation = rotation.twist.v_mps / rotation.twist.omega_radps;
  const double radius_translation = translation.twist.v_mps / translation.twist.omega_radps;
  EXPECT_LT(radius_rotation, 0.2 * radius_translation);
}

TEST(SlopedFunnelLane, SymmetricApproachHasNoSlopeXAndGoesStraight) {
  SlopedFunnelLaneOptions o;
  const auto r = ComputeSlopedFunnelLane(Map(kDest, 0.8, 0.0), o);
  ASSERT_TRUE(r.ok);
  EXPECT_NEAR(r.std_ratio, 0.8, 1e-9);  // constraint (5) holds
  EXPECT_NEAR(r.slope_y, 0.2, 1e-9);
  EXPECT_LT(std::abs(r.slope_x), o.turn_threshold);
  EXPECT_EQ(r.command, TurnCommand::kStraight);
  EXPECT_DOUBLE_EQ(r.twist.v_mps, o.max_speed_mps);
  EXPECT_EQ(r.twist.omega_radps, 0.0);
}

TEST(SlopedFunnelLane, TurnsInPlaceWhenStdRatioIsNearOne) {
  // A pure rotation between current and keyframe: same spread, everything shifted left.
  const auto r = ComputeSlopedFunnelLane(Map(kDest, 1.0, -40.0), {});
  ASSERT_TRUE(r.ok);
  EXPECT_NEAR(r.std_ratio, 1.0, 1e-9);
  EXPECT_EQ(r.command, TurnCommand::kLeft);
  EXPECT_EQ(r.twist.v_mps, 0.0);
  EXPECT_GT(r.twist.omega_radps, 0.0);
}

TEST(SlopedFunnelLane, TurnRateGrowsWithSlopeXAndSpeedWithSlopeY) {
  const auto small = ComputeSlopedFunnelLane(Map(kDest, 0.9, 12.0), {});
  const auto large = ComputeSlopedFunnelLane(Map(kDest, 0.9, 40.0), {});
  EXPECT_EQ(small.command, TurnCommand::kRight);
  EXPECT_EQ(large.command, TurnCommand::kRight);
  EXPECT_LT(large.twist.omega_radps, small.twist.omega_radps);  // more negative: faster right
  const auto wide = ComputeSlopedFunnelLane(Map(kDest, 0.7, 40.0), {});
  const auto sharp = ComputeSlopedFunnelLane(Map(kDest, 0.97, 40.0), {});
  EXPECT_GT(wide.twist.v_mps, sharp.twist.v_mps);
}

TEST(SlopedFunnelLane, NeedsTwoFeaturesWithSpread) {
  EXPECT_FALSE(ComputeSlopedFunnelLane({{10, 20}}, {}).ok);
  EXPECT_FALSE(ComputeSlopedFunnelLane({{10, 20}, {11, 20}}, {}).ok);
}

TEST(CheckSwitch, SwitchesOnceTheSpreadExceedsTheKeyframesAndMediansAgree) {
  SwitchOptions o;
  EXPECT_FALSE(CheckSwitch(Map(kDest, 0.9, 0.0), o).switch_now);  // not yet there
  const SwitchDecision passed = CheckSwitch(Map(kDest, 1.05, 0.0), o);
  EXPECT_TRUE(passed.switch_now);
  EXPECT_NEAR(passed.std_ratio, 1.05, 1e-9);
  const SwitchDecision misaligned = CheckSwitch(Map(kDest, 1.05, 40.0), o);
  EXPECT_FALSE(misaligned.switch_now);  // spread is right but the view is turned away
  EXPECT_NEAR(misaligned.ed_px, 40.0 + 0.05 * Median(kDest), 1e-9);
}

TEST(MseSwitch, SwitchesWhenTheErrorRisesAfterFalling) {
  MseSwitch s(2);
  EXPECT_FALSE(s.Update(Map(kDest, 0.7, 0.0)));
  EXPECT_FALSE(s.Update(Map(kDest, 0.8, 0.0)));
  EXPECT_FALSE(s.Update(Map(kDest, 0.95, 0.0)));
  EXPECT_FALSE(s.Update(Map(kDest, 1.1, 0.0)));  // |error| 0.05 -> 0.1: rises once
  EXPECT_TRUE(s.Update(Map(kDest, 1.2, 0.0)));   // twice: switch
  s.Reset();
  EXPECT_FALSE(s.Update(Map(kDest, 1.2, 0.0)));
  EXPECT_FALSE(s.Update(Map(kDest, 1.3, 0.0)));  // rising from the start: no decrease seen yet
  EXPECT_FALSE(s.Update(Map(kDest, 1.4, 0.0)));
}

// A pinhole view (f = 277 px, as a 60 degree 320 px camera) of a near object on the right (a car's
// side, 2.5 m ahead) and a far wall (12 m ahead, mostly left), from a camera `lateral_m` to the
// side of the keyframe's (negative: left) and `before_m` short of it.
std::vector<FeaturePoint> View(double lateral_m, double before_m) {
  const double f = 277.0;
  struct P3 {
    double x, y, z;
  };
  std::vector<P3> scene;
  for (double x = 1.0; x <= 2.21; x += 0.15)
    for (double y = -0.4; y <= 0.61; y += 0.2) scene.push_back({x, y, 2.5});
  for (double x = -4.0; x <= 1.01; x += 0.5)
    for (double y = -0.4; y <= 2.61; y += 0.5) scene.push_back({x, y, 12.0});
  std::vector<FeaturePoint> out;
  for (const P3& p : scene) {
    out.push_back({f * (p.x - lateral_m) / (p.z + before_m), f * p.y / (p.z + before_m),
                   f * p.x / p.z, f * p.y / p.z});
  }
  return out;
}

std::vector<FeaturePair> XOnly(const std::vector<FeaturePoint>& points) {
  std::vector<FeaturePair> out;
  for (const FeaturePoint& p : points) out.push_back({p.x_current_px, p.x_destination_px});
  return out;
}

TEST(LocalScale, CrossesOneAtTheKeyframeAlsoOffThePathWhereStdRatioDoesNot) {
  // On the taught path both say "not yet" before the keyframe and "there" at it.
  EXPECT_LT(CheckSwitch(XOnly(View(0.0, 0.3)), {}).std_ratio, 1.0);
  EXPECT_LT(MeasureLocalScale(View(0.0, 0.3), {}).ratio, 1.0);
  EXPECT_NEAR(MeasureLocalScale(View(0.0, 0.0), {}).ratio, 1.0, 1e-9);
  // 0.3 m to the left the near object's features spread wider: StdRatio passes 1 well before the
  // keyframe, the local scale does not.
  EXPECT_GT(CheckSwitch(XOnly(View(-0.3, 0.3)), {}).std_ratio, 1.0);
  const LocalScale before = MeasureLocalScale(View(-0.3, 0.3), {});
  ASSERT_TRUE(before.ok);
  EXPECT_LT(before.ratio, 1.0);
  EXPECT_GE(before.pairs, LocalScaleOptions{}.min_pairs);
  EXPECT_NEAR(MeasureLocalScale(View(-0.3, 0.0), {}).ratio, 1.0, 1e-9);
  EXPECT_GT(MeasureLocalScale(View(-0.3, -0.1), {}).ratio, 1.0);  // passed it
}

TEST(LocalScale, NeedsEnoughNearbyPairs) {
  // Features far apart in the keyframe lie on different objects: no pair qualifies.
  std::vector<FeaturePoint> sparse;
  for (int i = 0; i < 6; ++i) sparse.push_back({60.0 * i, 0.0, 50.0 * i, 0.0});
  const LocalScale s = MeasureLocalScale(sparse, {});
  EXPECT_FALSE(s.ok);
  EXPECT_EQ(s.pairs, 0);
  LocalScaleOptions wide;
  wide.max_pair_px = 120.0;
  wide.min_pairs = 5;
  const LocalScale w = MeasureLocalScale(sparse, wide);
  ASSERT_TRUE(w.ok);
  EXPECT_NEAR(w.ratio, 1.2, 1e-9);
}

TEST(FunnelLaneOptions, InvalidValuesNameTheField) {
  SlopedFunnelLaneOptions o;
  o.turn_threshold = -0.2;
  try {
    o.Validate();
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(
        std::string(e.what()).find("SlopedFunnelLaneOptions.turn_threshold = -0.2; must be >= 0"),
        std::string::npos);
  }
  LocalScaleOptions l;
  l.max_pair_px = 5.0;
  try {
    l.Validate();
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(
        std::string(e.what()).find("LocalScaleOptions.max_pair_px = 5; must be > min_pair_px"),
        std::string::npos);
  }
}

}  // namespace
}  // namespace mapless::control
