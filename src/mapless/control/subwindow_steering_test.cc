#include "mapless/control/subwindow_steering.h"

#include <gtest/gtest.h>

#include "mapless/core/check.h"

namespace mapless::control {
namespace {

constexpr int kWindows = 49;  // aligned indices of A..E: 0, 12, 24, 36, 48

TEST(SubWindowSteering, GoesStraightWhenAligned) {
  const std::vector<WindowCorrespondence> m = {{0, 0},  {1, 12}, {1, 13}, {2, 24},
                                               {3, 36}, {3, 35}, {4, 48}};
  const SubWindowSteering s = ComputeSubWindowSteering(m, kWindows, 1, {});
  ASSERT_TRUE(s.ok) << s.reason;
  EXPECT_NEAR(s.shift_windows, 0.0, 0.3);
  EXPECT_NEAR(s.twist.omega_radps, 0.0, 0.01);
  EXPECT_GT(s.twist.v_mps, 0.0);
}

// Fig. 2 of the paper: the scene sits further right in the route image (every window matches a
// higher index) and E falls outside it (an outlier): turn left.
TEST(SubWindowSteering, TurnsLeftWhenTheRouteViewLiesToTheRightAndDropsTheOutlier) {
  const std::vector<WindowCorrespondence> m = {{0, 6},  {1, 18}, {1, 19}, {2, 30},
                                               {2, 31}, {3, 42}, {4, 3}};
  const SubWindowSteering s = ComputeSubWindowSteering(m, kWindows, 1, {});
  ASSERT_TRUE(s.ok) << s.reason;
  EXPECT_NEAR(s.shift_windows, 6.3, 0.6);
  EXPECT_GT(s.twist.omega_radps, 0.0);
  EXPECT_EQ(s.outliers, 1);
  EXPECT_EQ(s.fit, "A-E");  // all windows, E removed as the outlier
}

TEST(SubWindowSteering, TurnsRightWhenTheRouteViewLiesToTheLeft) {
  const std::vector<WindowCorrespondence> m = {{1, 4},  {2, 16}, {2, 17}, {3, 28},
                                               {4, 40}, {4, 41}, {0, 30}};
  const SubWindowSteering s = ComputeSubWindowSteering(m, kWindows, 1, {});
  ASSERT_TRUE(s.ok) << s.reason;
  EXPECT_LT(s.shift_windows, -6.0);
  EXPECT_LT(s.twist.omega_radps, 0.0);
}

// A parked car passed closer on the right looms: D and E match stored windows further left than
// aligned. Read from all windows the robot would turn right, towards the car; the better-sloped
// half (A-C) says go straight.
TEST(SubWindowSteering, ReadsTheOrdinateFromTheHalfThatDoesNotLoom) {
  const std::vector<WindowCorrespondence> m = {{0, 0},  {1, 12}, {1, 13}, {2, 24},
                                               {3, 31}, {3, 32}, {4, 38}};
  SubWindowSteeringOptions halves;
  halves.prefer_undistorted_half = true;
  SubWindowSteeringOptions whole;
  whole.prefer_undistorted_half = false;
  const SubWindowSteering all = ComputeSubWindowSteering(m, kWindows, 1, whole);
  const SubWindowSteering half = ComputeSubWindowSteering(m, kWindows, 1, halves);
  ASSERT_TRUE(all.ok && half.ok);
  EXPECT_LT(all.twist.omega_radps, -0.01);
  EXPECT_EQ(half.fit, "A-C");
  EXPECT_NEAR(half.shift_windows, 0.0, 0.5);
}

TEST(SubWindowSteering, StopsWithAReasonWhenNothingIsConsistent) {
  const std::vector<WindowCorrespondence> m = {{0, 40}, {1, 2}, {2, 45}, {3, 1}, {4, 20}};
  const SubWindowSteering s = ComputeSubWindowSteering(m, kWindows, 1, {});
  EXPECT_FALSE(s.ok);
  EXPECT_FALSE(s.reason.empty());
  EXPECT_EQ(s.twist.v_mps, 0.0);
  EXPECT_EQ(s.twist.omega_radps, 0.0);
}

TEST(SubWindowSteering, RejectsOutOfRangeCorrespondences) {
  EXPECT_THROW(ComputeSubWindowSteering({{5, 0}}, kWindows, 1, {}), InputError);
  SubWindowSteeringOptions bad;
  bad.slope_tolerance = 2.0;
  EXPECT_THROW(ComputeSubWindowSteering({}, kWindows, 1, bad), InputError);
}

}  // namespace
}  // namespace mapless::control
