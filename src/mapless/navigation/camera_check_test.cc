#include "mapless/navigation/camera_check.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "mapless/core/check.h"
#include "mapless/sim/camera_faults.h"
#include "mapless/sim/scenario.h"
#include "mapless/sim/simulation.h"

namespace mapless::navigation {
namespace {

const Twist2 kDriving{0.3, 0.0};
const Twist2 kStopped{0.0, 0.0};

cv::Mat Textured(int seed) {
  cv::Mat image(240, 320, CV_8UC1);
  cv::randu(image, 0, 1);  // reset
  cv::RNG rng(static_cast<std::uint64_t>(seed));
  rng.fill(image, cv::RNG::UNIFORM, 40, 200);
  return image;
}

TEST(CameraMonitor, TexturedFramesAreUsable) {
  CameraMonitor monitor;
  for (int i = 0; i < 5; ++i) EXPECT_TRUE(monitor.Check(Textured(i), kDriving).usable());
  cv::Mat colour;
  cv::cvtColor(Textured(9), colour, cv::COLOR_GRAY2BGR);
  EXPECT_TRUE(monitor.Check(colour, kDriving).usable());
}

TEST(CameraMonitor, NamesEachFault) {
  CameraMonitor monitor;
  EXPECT_EQ(monitor.Check(cv::Mat(), kDriving).fault, CameraFault::kNoImage);
  const CameraCheck black = monitor.Check(cv::Mat(240, 320, CV_8UC1, cv::Scalar(3)), kDriving);
  EXPECT_EQ(black.fault, CameraFault::kBlack);
  EXPECT_NE(black.reason.find("black frame (mean grey level 3.0)"), std::string::npos)
      << black.reason;
  cv::Mat bright = Textured(1);
  bright.convertTo(bright, -1, 8.0);
  EXPECT_EQ(monitor.Check(bright, kDriving).fault, CameraFault::kOverExposed);
  EXPECT_EQ(monitor.Check(cv::Mat(240, 320, CV_8UC1, cv::Scalar(150)), kDriving).fault,
            CameraFault::kFeatureless);
  cv::Mat deep(240, 320, CV_16UC1, cv::Scalar(1000));
  EXPECT_EQ(monitor.Check(deep, kDriving).fault, CameraFault::kNoImage);
}

TEST(CameraMonitor, ARepeatedFrameIsFrozenOnlyAfterTwoMovesAndUntilTheImageChanges) {
  CameraMonitor monitor;
  const cv::Mat a = Textured(1);
  EXPECT_TRUE(monitor.Check(a, kStopped).usable());
  EXPECT_TRUE(monitor.Check(a.clone(), kStopped).usable());  // standing still: the same view
  // Told to move on the frame before: the robot may not have started when this one was taken.
  EXPECT_TRUE(monitor.Check(a.clone(), kDriving).usable());
  EXPECT_EQ(monitor.Check(a.clone(), kDriving).fault, CameraFault::kFrozen);
  // Latched: still frozen after the robot has stopped, as long as the image does not change.
  EXPECT_EQ(monitor.Check(a.clone(), kStopped).fault, CameraFault::kFrozen);
  EXPECT_TRUE(monitor.Check(Textured(2), kStopped).usable());
  EXPECT_TRUE(monitor.Check(Textured(2), Twist2{0.0, 0.3}).usable());
  EXPECT_EQ(monitor.Check(Textured(2), Twist2{0.0, 0.3}).fault, CameraFault::kFrozen);
}

TEST(CameraMonitor, RejectsBadOptions) {
  CameraCheckOptions o;
  o.max_saturated_fraction = 0.0;
  EXPECT_THROW(CameraMonitor{o}, InputError);
}

// No false alarm on nominal frames: every tenth frame of each built-in scenario's teach drive,
// and of its repeat world variant.
TEST(CameraMonitor, NoFaultOnTheBuiltInScenariosTeachDrives) {
  for (const std::string& name : sim::BuiltinScenarioNames()) {
    const sim::Scenario s = sim::LoadScenario(name);
    std::vector<Pose2> poses;
    sim::DriveOptions options;
    options.render_frames = false;
    sim::DriveTaughtPath(s, options, [&](const sim::DriveFrame& f) {
      if (f.index % 10 == 0) poses.push_back(f.truth);
    });
    ASSERT_GT(poses.size(), 3U) << name;
    for (const sim::World& world : {s.world, sim::ApplyVariant(s.world, s.repeat_variant)}) {
      sim::Simulation sim(world, s.camera, {}, 1);
      const int r = sim.AddRobot(poses.front(), s.robot);
      CameraMonitor monitor;
      for (std::size_t i = 0; i < poses.size(); ++i) {
        sim.PlaceRobot(r, poses[i]);
        // The frozen test needs a moving robot and is covered above; stopping points at the end
        // of legs legitimately repeat the view.
        const CameraCheck check = monitor.Check(sim.Render(r), kStopped);
        EXPECT_TRUE(check.usable()) << name << " pose " << i << ": " << check.reason;
      }
    }
  }
}

TEST(FaultyCamera, AppliesEachFaultOnlyInsideItsWindow) {
  const cv::Mat a = Textured(1);
  const cv::Mat b = Textured(2);
  sim::FaultyCamera camera({{sim::CameraFaultKind::kFrozen, 0.2, 0.4},
                            {sim::CameraFaultKind::kDropped, 0.4, 0.5},
                            {sim::CameraFaultKind::kFeatureless, 0.5, 0.6}});
  EXPECT_EQ(cv::norm(camera.Apply(a, 10.0), a, cv::NORM_INF), 0.0);  // t = 0
  EXPECT_EQ(cv::norm(camera.Apply(b, 10.1), b, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(camera.Apply(a, 10.2), b, cv::NORM_INF), 0.0);  // frozen on b
  EXPECT_EQ(cv::norm(camera.Apply(a, 10.3), b, cv::NORM_INF), 0.0);
  EXPECT_TRUE(camera.Apply(a, 10.4).empty());
  cv::Scalar mean, stddev;
  cv::meanStdDev(camera.Apply(a, 10.5), mean, stddev);
  EXPECT_NEAR(mean[0], 150.0, 1.0);
  EXPECT_LT(stddev[0], 1.5);
  EXPECT_EQ(cv::norm(camera.Apply(a, 10.6), a, cv::NORM_INF), 0.0);
  EXPECT_EQ(sim::ParseCameraFaultKind("over-exposed"), sim::CameraFaultKind::kOverExposed);
  EXPECT_THROW(sim::ParseCameraFaultKind("smoke"), InputError);
  EXPECT_THROW(sim::FaultyCamera({{sim::CameraFaultKind::kBlack, 1.0, 1.0}}), InputError);
}

}  // namespace
}  // namespace mapless::navigation
