#include "mapless/control/visual_potential.h"

#include <gtest/gtest.h>

#include <cmath>

namespace mapless::control {
namespace {

constexpr double kPi = 3.14159265358979323846;

TEST(RepulsionField, PointsAwayFromAnObstacleOnTheRight) {
  cv::Mat d(240, 320, CV_8U, cv::Scalar(255));
  d(cv::Rect(220, 0, 100, 200)).setTo(0);  // an obstacle in the right part of the view
  const cv::Mat g = RepulsionField(d, VisualPotentialOptions{});
  ASSERT_EQ(g.size(), d.size());
  const cv::Scalar mean = cv::mean(g);
  EXPECT_LT(mean[0], 0.0);  // to the left, away from the obstacle
  const VisualPotentialOptions options;
  const PotentialCommand c = CommandFromForce(ControlForce(g), options);
  EXPECT_GT(c.twist.omega_radps, 0.0);  // turn left
}

TEST(RepulsionField, IsZeroWithoutObstacles) {
  const cv::Mat d(240, 320, CV_8U, cv::Scalar(255));
  EXPECT_LT(cv::norm(RepulsionField(d, VisualPotentialOptions{}), cv::NORM_INF), 1e-4);
}

TEST(CommandFromForce, FollowsEq16And17) {
  VisualPotentialOptions o;
  o.max_translation_mps = 0.3;
  o.max_rotation_radps = 0.6;
  const PotentialCommand ahead = CommandFromForce({0.0, -2.0}, o);  // straight up the image
  EXPECT_NEAR(ahead.theta_rad, 0.0, 1e-12);
  EXPECT_NEAR(ahead.twist.v_mps, 0.3, 1e-12);
  EXPECT_NEAR(ahead.twist.omega_radps, 0.0, 1e-12);
  const PotentialCommand left = CommandFromForce({-1.0, -1.0}, o);  // up and to the left
  EXPECT_NEAR(left.theta_rad, kPi / 4, 1e-12);
  EXPECT_NEAR(left.twist.v_mps, 0.3 * std::cos(kPi / 4), 1e-12);
  EXPECT_NEAR(left.twist.omega_radps, 0.6 * std::sin(kPi / 4), 1e-12);
  const PotentialCommand right = CommandFromForce({3.0, 0.0}, o);  // to the right: turn in place
  EXPECT_NEAR(right.theta_rad, -kPi / 2, 1e-12);
  EXPECT_NEAR(right.twist.v_mps, 0.0, 1e-12);
  EXPECT_NEAR(right.twist.omega_radps, -0.6, 1e-12);
  const PotentialCommand none = CommandFromForce({0.0, 0.0}, o);
  EXPECT_EQ(none.twist.v_mps, 0.0);
  EXPECT_EQ(none.twist.omega_radps, 0.0);
}

TEST(DesiredFlow, MixesTheTranslationalAndRotationalFlows) {
  const cv::Mat t(4, 4, CV_32FC2, cv::Scalar(0.0, 2.0));
  const cv::Mat r(4, 4, CV_32FC2, cv::Scalar(-3.0, 0.0));
  EXPECT_LT(cv::norm(DesiredFlow(t, r, 0.0) - t, cv::NORM_INF), 1e-6);
  EXPECT_LT(cv::norm(DesiredFlow(t, r, kPi / 2) - r, cv::NORM_INF), 1e-6);
  const cv::Vec2f mix = DesiredFlow(t, r, kPi / 6).at<cv::Vec2f>(1, 1);
  EXPECT_NEAR(mix[0], -3.0 * 0.5, 1e-5);
  EXPECT_NEAR(mix[1], 2.0 * std::cos(kPi / 6), 1e-5);
}

TEST(PotentialField, AttractsOnlyOnThePlane) {
  cv::Mat d(2, 2, CV_8U, cv::Scalar(255));
  d.at<uchar>(0, 0) = 0;
  const cv::Mat g(2, 2, CV_32FC2, cv::Scalar(1.0, 0.0));
  const cv::Mat u(2, 2, CV_32FC2, cv::Scalar(0.0, 2.0));  // ground streams down the image
  const cv::Mat p = PotentialField(d, g, u, VisualPotentialOptions{});
  EXPECT_EQ(p.at<cv::Vec2f>(0, 0), cv::Vec2f(1.f, 0.f));   // obstacle: repulsion only
  EXPECT_EQ(p.at<cv::Vec2f>(1, 1), cv::Vec2f(1.f, -2.f));  // plane: g - u, forward is up
  const cv::Vec2d f = ControlForce(p);
  EXPECT_NEAR(f[0], 1.0, 1e-9);
  EXPECT_NEAR(f[1], -1.5, 1e-9);
}

}  // namespace
}  // namespace mapless::control
