#include "mapless/control/detour.h"

#include <gtest/gtest.h>

#include <cmath>

#include "mapless/core/check.h"

namespace mapless::control {
namespace {

constexpr double kRobotRadius = 0.2;

// A stand-in for the obstacle watch: a disc on the ground is seen when it overlaps the strip
// +-0.27 m wide from 0.9 m to 2.1 m ahead of the robot, and only after the robot has driven 8 cm
// straight (the watch's baseline).
struct FakeWatch {
  double ox, oy, r;
  double straight_m = 0.0;
  AheadView Look(const Pose2& pose, const Twist2& last, double dt) {
    straight_m = last.omega_radps == 0.0 && last.v_mps > 0.0 ? straight_m + last.v_mps * dt : 0.0;
    if (straight_m < 0.08) return AheadView::kUnknown;
    double x = 0.0, y = 0.0;
    pose.Inverse().Apply(ox, oy, &x, &y);
    const bool in = x + r > 0.9 && x - r < 2.1 && std::abs(y) < 0.27 + r;
    return in ? AheadView::kBlocked : AheadView::kFree;
  }
};

TEST(Detour, GoesRoundABoxOnTheLineAndRejoinsItBeyond) {
  for (const double oy : {-0.1, 0.0, 0.12}) {
    FakeWatch watch{1.1, oy, 0.25};
    // The side: away from the box's offset (left of the line: round by the right).
    const double side_theta = oy > 0.0 ? -0.5 : 0.5;
    // The box's extent as the image would give it (a little wider: the safe side).
    ObstacleExtent extent;
    extent.found = true;
    extent.left_m = oy + 0.3;
    extent.right_m = oy - 0.3;
    Detour detour({0.0, 0.0, 0.0}, side_theta, extent, 0.27, DetourOptions{});
    Pose2 pose;
    Twist2 last;
    double closest = 1e9;
    int steps = 0;
    for (; steps < 2000 && !detour.finished(); ++steps) {
      const AheadView view = watch.Look(pose, last, 0.1);
      last = detour.Command(pose, view, 0.3);
      pose = IntegrateTwist(pose, last, 0.1);
      closest = std::min(closest, std::hypot(pose.x_m - 1.1, pose.y_m - oy) - 0.25);
    }
    EXPECT_EQ(detour.phase(), DetourPhase::kDone) << "box at y = " << oy;
    EXPECT_GT(closest, kRobotRadius + 0.05) << "box at y = " << oy;
    EXPECT_GT(pose.x_m, 1.35 + 0.3);            // beyond the box
    EXPECT_LT(std::abs(pose.y_m), 0.1 + 0.01);  // back on the line
    EXPECT_EQ(detour.side() < 0.0, oy > 0.0);
  }
}

TEST(Detour, FailsWhenTheWayStaysBlockedBeyondTheLargestOffset) {
  DetourOptions o;
  o.max_offset_m = 0.9;
  Detour detour({0.0, 0.0, 0.0}, 0.3, ObstacleExtent{}, 0.27, o);
  Pose2 pose;
  Twist2 last;
  for (int i = 0; i < 3000 && !detour.finished(); ++i) {
    // A wall across the way: every look is blocked.
    const AheadView view =
        last.omega_radps == 0.0 && last.v_mps > 0.0 ? AheadView::kSuspect : AheadView::kUnknown;
    last = detour.Command(pose, view, 0.3);
    pose = IntegrateTwist(pose, last, 0.1);
  }
  EXPECT_EQ(detour.phase(), DetourPhase::kFailed);
  EXPECT_GT(pose.y_m, 0.64 - 0.05);  // it stepped aside (0.64 m first) before giving up
  EXPECT_LT(pose.y_m, 0.9 + 0.15);   // and stopped stepping aside beyond the largest offset
  EXPECT_EQ(detour.Command(pose, AheadView::kFree, 0.3).v_mps, 0.0);
}

// A wall beside the robot on the chosen side, seen only when stepping aside turns the camera to
// it: the detour goes round by the other side; with walls on both sides it fails.
TEST(Detour, AWallInTheWayOfTheStepAsideSendsItRoundTheOtherSide) {
  for (const bool both : {false, true}) {
    FakeWatch box{1.1, 0.0, 0.2};
    Detour detour({0.0, 0.0, 0.0}, 0.5, ObstacleExtent{}, 0.27, DetourOptions{});
    EXPECT_GT(detour.side(), 0.0);
    Pose2 pose;
    Twist2 last;
    double max_left = 0.0;
    for (int i = 0; i < 3000 && !detour.finished(); ++i) {
      AheadView view = box.Look(pose, last, 0.1);
      // Facing a wall: turned towards it (more than 0.5 rad) and within 0.5 m of the line.
      const bool left_wall = pose.y_m > 0.5 && pose.theta_rad > 0.5;
      const bool right_wall = pose.y_m < -0.5 && pose.theta_rad < -0.5;
      if (left_wall || (both && right_wall)) view = AheadView::kBlocked;
      last = detour.Command(pose, view, 0.3);
      pose = IntegrateTwist(pose, last, 0.1);
      max_left = std::max(max_left, pose.y_m);
    }
    if (both) {
      EXPECT_EQ(detour.phase(), DetourPhase::kFailed);
      EXPECT_LT(pose.y_m, -0.5 + 0.05);  // it tried the right as well
    } else {
      EXPECT_EQ(detour.phase(), DetourPhase::kDone);
      EXPECT_LT(detour.side(), 0.0);  // round by the right
      EXPECT_GT(pose.x_m, 1.1 + 0.2 + kRobotRadius);
      EXPECT_LT(max_left, 0.5 + 0.1);
    }
  }
}

// Eq. 8-16 on the watch's map: obstacle points left of the image's centre push to the right
// (theta < 0), right of it to the left; nothing in the way and the destination ahead: theta 0.
TEST(DetourAngle, TurnsAwayFromTheObstaclesSide) {
  std::vector<cv::Point2f> left, right;
  for (int y = 150; y < 200; y += 10) {
    for (int x = 100; x < 150; x += 10) {
      left.emplace_back(static_cast<float>(x), static_cast<float>(y));
      right.emplace_back(static_cast<float>(320 - x), static_cast<float>(y));
    }
  }
  VisualPotentialOptions o;
  o.repulsion_gain = 2.0;
  // Only the sign is used (the turn-out angle is clamped): a sigma of half the image makes the
  // force's side component small.
  EXPECT_LT(DetourAngle(left, {320, 240}, 0.55, 10.0, 0.0, o), -0.005);
  EXPECT_GT(DetourAngle(right, {320, 240}, 0.55, 10.0, 0.0, o), 0.005);
  EXPECT_NEAR(DetourAngle({}, {320, 240}, 0.55, 10.0, 0.0, o), 0.0, 1e-6);
  // A destination to the left pulls the free view's force to the left.
  EXPECT_GT(DetourAngle({}, {320, 240}, 0.55, 10.0, 0.5, o), 0.1);
}

// With an extent wider than max_offset_m allows, the detour fails at once (the robot stops
// instead).
TEST(Detour, AnObstacleTooWideToStepPastFailsAtOnce) {
  ObstacleExtent wide;
  wide.found = true;
  wide.left_m = 2.0;
  wide.right_m = -2.0;
  Detour detour({0.0, 0.0, 0.0}, 0.2, wide, 0.27, DetourOptions{});
  EXPECT_EQ(detour.phase(), DetourPhase::kFailed);
  // Nothing measured: the obstacle may reach the strip's edge (0.27 m), so the first step is
  // past it by the strip's half-width and the margin; an extent inside the strip the same.
  Detour plain({0.0, 0.0, 0.0}, 0.2, ObstacleExtent{}, 0.27, DetourOptions{});
  EXPECT_NEAR(plain.offset_m(), 0.27 + 0.27 + DetourOptions{}.margin_m, 1e-9);
  ObstacleExtent narrow;
  narrow.found = true;
  narrow.left_m = 0.05;
  narrow.right_m = -0.4;
  EXPECT_NEAR(Detour({0.0, 0.0, 0.0}, 0.2, narrow, 0.27, DetourOptions{}).offset_m(),
              0.27 + 0.27 + DetourOptions{}.margin_m, 1e-9);
  EXPECT_NEAR(Detour({0.0, 0.0, 0.0}, -0.2, narrow, 0.27, DetourOptions{}).offset_m(),
              0.4 + 0.27 + DetourOptions{}.margin_m, 1e-9);
}

// The strip's geometry: +-0.27 m is +-80 px at the bottom row of a 320x240 image. The extent
// is measured at the bottom row, over the off-plane points of the region's rows next to the
// region's own, not over a wall farther aside nor over points above the region's rows.
TEST(MeasureObstacleExtent, GrowsOverNeighboursButNotOverAFarWall) {
  const cv::Size image(320, 240);
  const auto at = [](double lateral_m, double row) {
    return cv::Point2f(static_cast<float>(160.0 - lateral_m / 0.27 * 80.0),
                       static_cast<float>(row));
  };
  std::vector<cv::Point2f> region{at(-0.1, 200), at(0.0, 190), at(0.2, 200)};
  std::vector<cv::Point2f> off = region;
  for (double l = 0.25; l <= 0.46; l += 0.1) off.push_back(at(l, 180));  // the obstacle beyond
  off.push_back(at(-0.2, 200));
  off.push_back(at(0.8, 200));   // a wall on the left, beyond a gap
  off.push_back(at(-0.3, 150));  // above the region's rows (row 173 down): not counted
  const ObstacleExtent e = MeasureObstacleExtent(region, off, image, 0.5, 0.72, 0.27);
  ASSERT_TRUE(e.found);
  EXPECT_NEAR(e.left_m, 0.45, 1e-3);
  EXPECT_NEAR(e.right_m, -0.2, 1e-3);
  EXPECT_FALSE(MeasureObstacleExtent({}, off, image, 0.5, 0.72, 0.27).found);
}

TEST(DetourOptions, ABadFieldIsNamed) {
  DetourOptions o;
  o.turn_out_max_rad = 2.0;
  try {
    o.Validate();
    FAIL() << "accepted turn_out_max_rad = 2";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("turn_out_max_rad"), std::string::npos);
  }
}

}  // namespace
}  // namespace mapless::control
