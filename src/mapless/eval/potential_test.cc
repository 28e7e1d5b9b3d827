// Visual-potential navigation on the simulator: calibration, its file format, corridor driving,
// a wall ahead, and reaching a destination.
#include "mapless/eval/potential.h"

#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/core.hpp>

#include "mapless/core/testing.h"
#include "mapless/sim/scenario.h"
#include "mapless/sim/simulation.h"

namespace mapless::eval {
namespace {

using navigation::PotentialStatus;

const navigation::PlanarFlowCalibration& CorridorCalibration() {
  static const navigation::PlanarFlowCalibration c = CalibrateOnSimulator(
      sim::LoadScenario("corridor_straight_3p5m"), navigation::PotentialNavOptions{});
  return c;
}

TEST(PlanarFlowCalibration, ForwardFlowStreamsDownAndRotationFlowsSideways) {
  const auto& c = CorridorCalibration();
  const cv::Mat ut = ground::PlanarFlow(c.translational, {c.width, c.height});
  const cv::Mat ur = ground::PlanarFlow(c.rotational, {c.width, c.height});
  // Driving forward, the ground below the camera moves down the image; turning left
  // (counter-clockwise), the image content moves right.
  const cv::Vec2f bottom = ut.at<cv::Vec2f>(c.height - 10, c.width / 2);
  EXPECT_GT(bottom[1], 1.0F);
  EXPECT_LT(std::abs(bottom[0]), 0.5F);
  EXPECT_GT(cv::mean(ur)[0], 1.0);
}

TEST(PlanarFlowCalibration, YamlRoundTripAndErrorsNameTheSource) {
  const auto& c = CorridorCalibration();
  const auto back = navigation::CalibrationFromYaml(navigation::CalibrationToYaml(c), "cal.yaml");
  EXPECT_EQ(back.width, c.width);
  EXPECT_NEAR(back.speed_mps, c.speed_mps, 1e-12);
  EXPECT_LT(cv::norm(back.translational, c.translational, cv::NORM_INF), 1e-12);
  EXPECT_LT(cv::norm(back.rotational, c.rotational, cv::NORM_INF), 1e-12);
  std::string text = navigation::CalibrationToYaml(c);
  text.replace(text.find("speed_mps:"), 10, "speed_mps: -1 #");
  const std::string err =
      testing::InputErrorOf([&] { navigation::CalibrationFromYaml(text, "cal.yaml"); });
  EXPECT_NE(err.find("cal.yaml"), std::string::npos) << err;
  EXPECT_NE(err.find("speed_mps"), std::string::npos) << err;
  EXPECT_NE(testing::InputErrorOf([] {
              navigation::CalibrationFromYaml("format: x\n", "c.yaml");
            }).find("c.yaml"),
            std::string::npos);
}

TEST(PotentialNavigator, StopsAndTurnsInPlaceWhenNothingIsPlanar) {
  // Independent noise images: no flow field agrees with any plane, so there is no ground.
  navigation::PotentialNavigator nav(CorridorCalibration(), navigation::PotentialNavOptions{});
  Rng rng(3);
  Pose2 odometry;
  bool searched = false;
  for (int i = 0; i < 12; ++i) {
    cv::Mat noise(240, 320, CV_8UC1);
    cv::randu(noise, cv::Scalar(0), cv::Scalar(255));
    const navigation::PotentialStep step = nav.Update(noise, odometry);
    // Only the one-frame creep may translate; never faster.
    EXPECT_LE(step.command.v_mps, 0.25 * 0.2 + 1e-12) << i;
    if (step.status == PotentialStatus::kSearching) {
      searched = true;
      EXPECT_EQ(step.command.v_mps, 0.0);
      EXPECT_NE(step.command.omega_radps, 0.0);
      EXPECT_NE(step.reason.find("no ground plane"), std::string::npos) << step.reason;
    }
    odometry = IntegrateTwist(odometry, step.command, 0.1);
  }
  EXPECT_TRUE(searched);
}

sim::Scenario ShortCorridor() {
  sim::Scenario s = sim::LoadScenario("corridor_straight_3p5m");
  s.teach_path.back().target = Eigen::Vector2d(3.0, 0.0);
  return s;
}

TEST(PotentialNavigation, DrivesDownTheCorridorWithoutTouchingAWall) {
  PotentialRunOptions o;
  o.start_lateral_m = 0.4;
  const PotentialRun run = RunPotential(ShortCorridor(), CorridorCalibration(), o);
  EXPECT_TRUE(run.success) << run.status;
  EXPECT_FALSE(run.collided);
  // Same scenario, seed and options: the same trajectory.
  const PotentialRun again = RunPotential(ShortCorridor(), CorridorCalibration(), o);
  ASSERT_EQ(again.path.size(), run.path.size());
  EXPECT_EQ(again.path.back().x_m, run.path.back().x_m);
  EXPECT_EQ(again.path.back().y_m, run.path.back().y_m);
}

TEST(PotentialNavigation, TwentyPercentOfTheGroundMapInvertedStillDrivesThrough) {
  // The paper's image-noise experiment (Section 5.2): the safety window must judge the detected
  // ground, not the perturbed map, or the robot never moves.
  PotentialRunOptions o;
  o.nav.plane_noise_fraction = 0.2;
  o.seed = 3;
  o.nav.noise_seed = 3;
  const PotentialRun run = RunPotential(ShortCorridor(), CorridorCalibration(), o);
  EXPECT_TRUE(run.success) << run.status;
}

TEST(PotentialNavigation, AWallAheadTurnsTheRobotAwayBeforeItTouches) {
  // Facing the end wall of the corridor (x = 13) from 1 m, heading straight at it.
  sim::Scenario s = sim::LoadScenario("corridor_straight_3p5m");
  s.teach_start = Pose2{11.9, 0.3, 0.0};
  sim::Simulation sim(s.world, s.camera, {}, 5);
  const int r = sim.AddRobot(s.teach_start, s.robot);
  navigation::PotentialNavigator nav(CorridorCalibration(), navigation::PotentialNavOptions{});
  double closest = 1e9;
  for (int i = 0; i < 120 && !sim.collided(r); ++i) {
    const navigation::PotentialStep step = nav.Update(sim.Render(r), sim.robot(r).odometry());
    sim.SetCommand(r, step.command);
    sim.Advance(0.1);
    closest = std::min(closest, 13.0 - sim.robot(r).pose().x_m);
  }
  EXPECT_FALSE(sim.collided(r));
  EXPECT_GT(closest, s.robot.radius_m);
  // It turned away from the wall.
  EXPECT_GT(std::abs(WrapAngle(sim.robot(r).pose().theta_rad)), DegToRad(45.0));
}

TEST(PotentialNavigation, ReachesADestinationPastTheObstacles) {
  const sim::Scenario s = sim::LoadScenario("obstacle_field");
  const auto calibration = CalibrateOnSimulator(s, navigation::PotentialNavOptions{});
  PotentialRunOptions o;
  o.destination = s.destinations.at(1);
  const PotentialRun run = RunPotential(s, calibration, o);
  EXPECT_TRUE(run.success) << run.status << ", " << run.final_error_m << " m from the goal";
  EXPECT_LE(run.final_error_m, 0.3);
}

TEST(Inclusion, CoarserLayersMostlyContainTheFinerPlane) {
  // Table 1's measure on a slow drive down the corridor with the paper's detector options.
  const InclusionResult r = InclusionOnSimulator(sim::LoadScenario("corridor_straight_3p5m"),
                                                 ground::DominantPlaneOptions{}, 6);
  EXPECT_EQ(r.pairs, 6);
  EXPECT_GE(r.frames, 4);
  ASSERT_EQ(r.inclusion.size(), 3U);
  for (double p : r.inclusion) {
    EXPECT_GT(p, 0.6);
    EXPECT_LE(p, 1.0);
  }
}

TEST(TrajectoryDeviation, IsTheSpreadOfTheSignedOffsetFromTheCleanPath) {
  std::vector<Pose2> clean, noisy;
  for (int i = 0; i <= 100; ++i) {
    clean.push_back({0.1 * i, 0.0, 0.0});
    noisy.push_back({0.1 * i, (i % 2 == 0 ? 0.05 : -0.05), 0.0});
  }
  EXPECT_NEAR(TrajectoryDeviationStd(clean, noisy), 0.05, 1e-3);
  EXPECT_NEAR(SignedDistanceToPath(clean, 3.0, 0.2), 0.2, 1e-12);
  EXPECT_NEAR(SignedDistanceToPath(clean, 3.0, -0.2), -0.2, 1e-12);
  EXPECT_NEAR(TrajectoryDeviationStd(clean, clean), 0.0, 1e-12);
}

}  // namespace
}  // namespace mapless::eval
