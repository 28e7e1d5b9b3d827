// Camera faults on the simulator, for each method: a black camera, a frozen camera, a dropped
// source, an over-exposed camera and a featureless view, one second each, two seconds apart, in
// one run. On every faulty frame the robot must be told to stop, with the fault as the reason (so
// it stops within one control period); after each fault it must drive again; and the run must
// still end where it should.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <string>
#include <vector>

#include "mapless/eval/eigenspace.h"
#include "mapless/eval/potential.h"
#include "mapless/eval/teach_repeat.h"
#include "mapless/navigation/camera_check.h"
#include "mapless/sim/camera_faults.h"
#include "mapless/sim/scenario.h"

namespace mapless::eval {
namespace {

using sim::CameraFaultKind;

struct Frame {
  Twist2 command;
  std::string reason;
};

std::vector<sim::CameraFaultWindow> Schedule() {
  return {{CameraFaultKind::kBlack, 4.0, 5.0},
          {CameraFaultKind::kFrozen, 7.0, 8.0},
          {CameraFaultKind::kDropped, 10.0, 11.0},
          {CameraFaultKind::kOverExposed, 13.0, 14.0},
          {CameraFaultKind::kFeatureless, 16.0, 17.0}};
}

std::string ExpectedReason(CameraFaultKind kind) {
  switch (kind) {
    case CameraFaultKind::kBlack:
      return CameraFaultName(navigation::CameraFault::kBlack);
    case CameraFaultKind::kFrozen:
      return CameraFaultName(navigation::CameraFault::kFrozen);
    case CameraFaultKind::kDropped:
      return CameraFaultName(navigation::CameraFault::kNoImage);
    case CameraFaultKind::kOverExposed:
      return CameraFaultName(navigation::CameraFault::kOverExposed);
    case CameraFaultKind::kFeatureless:
      return CameraFaultName(navigation::CameraFault::kFeatureless);
  }
  return "?";
}

bool Moving(const Twist2& c) { return c.v_mps != 0.0 || c.omega_radps != 0.0; }

// Frame k is seen at k * period after the first frame (FaultyCamera's clock).
void CheckFaultHandling(const std::vector<Frame>& frames, double period_s) {
  const navigation::CameraCheckOptions camera;
  for (const sim::CameraFaultWindow& w : Schedule()) {
    const std::string name = sim::CameraFaultKindName(w.kind);
    const int first = static_cast<int>(std::ceil(w.start_s / period_s - 1e-6));
    const int last = static_cast<int>(std::ceil(w.end_s / period_s - 1e-6)) - 1;
    ASSERT_LT(last, static_cast<int>(frames.size()))
        << "the run ended before the " << name << " fault";
    int flagged = 0;
    for (int k = first; k <= last; ++k) {
      const Frame& f = frames[static_cast<std::size_t>(k)];
      // A frozen image is only recognisable once the robot was told to move on the two frames
      // before; from then on the fault holds until the image changes (camera_check.h).
      const auto told_to_move = [&](int j) {
        const Twist2& c = frames[static_cast<std::size_t>(j)].command;
        return std::abs(c.v_mps) > camera.moving_speed_mps ||
               std::abs(c.omega_radps) > camera.moving_rate_radps;
      };
      const bool must_flag = w.kind != CameraFaultKind::kFrozen || flagged > 0 ||
                             (told_to_move(k - 1) && told_to_move(k - 2));
      if (!must_flag) continue;
      EXPECT_FALSE(Moving(f.command)) << name << " fault, frame " << k << ": " << f.reason;
      EXPECT_NE(f.reason.find(ExpectedReason(w.kind)), std::string::npos)
          << name << " fault, frame " << k << ": reason '" << f.reason << "'";
      ++flagged;
    }
    EXPECT_GE(flagged, last - first) << name;
    // Resumes: drives again within 1.5 s of the fault's end.
    bool resumed = false;
    int resumed_at = -1;
    for (int k = last + 1; k < static_cast<int>(frames.size()) && k <= last + 15 && !resumed; ++k) {
      resumed = Moving(frames[static_cast<std::size_t>(k)].command);
      resumed_at = k;
    }
    EXPECT_TRUE(resumed) << "did not drive again after the " << name << " fault";
    std::cout << "  " << name << ": stopped on " << flagged << "/" << (last - first + 1)
              << " faulty frames, driving again " << (resumed_at - last) * period_s
              << " s after the fault\n";
  }
}

TEST(CameraFaults, TeachAndRepeatStopsOnEachFaultAndFinishesTheRoute) {
  const sim::Scenario scenario = sim::LoadScenario("table1_almost_straight");
  const TaughtRoute taught = TeachOnSimulator(scenario, navigation::TeachOptions{});
  RepeatRunOptions o;
  o.camera_faults = Schedule();
  const double speed = RepeatSpeedFor(scenario, o.max_repeat_speed_mps);
  o.repeat.sloped.max_speed_mps = speed;
  std::vector<Frame> frames;
  const RepeatRun run = RepeatOnSimulator(
      scenario, taught, o, [&](const Pose2&, const cv::Mat&, const navigation::RepeatStep& s) {
        frames.push_back({s.command, s.reason});
      });
  CheckFaultHandling(frames, 1.0 / scenario.camera.rate_hz);
  EXPECT_TRUE(run.success) << run.status << ", " << run.final_error_m << " m from the end";
  EXPECT_FALSE(run.collided);
}

TEST(CameraFaults, VisualPotentialStopsOnEachFaultAndDrivesDownTheCorridor) {
  const sim::Scenario scenario = sim::LoadScenario("corridor_straight_3p5m");
  const auto calibration = CalibrateOnSimulator(scenario, navigation::PotentialNavOptions{});
  PotentialRunOptions o;
  o.camera_faults = Schedule();
  std::vector<Frame> frames;
  const PotentialRun run =
      RunPotential(scenario, calibration, o,
                   [&](const Pose2&, const cv::Mat&, const navigation::PotentialStep& s) {
                     frames.push_back({s.command, s.reason});
                   });
  CheckFaultHandling(frames, 1.0 / scenario.camera.rate_hz);
  EXPECT_TRUE(run.success) << run.status;
  EXPECT_FALSE(run.collided);
}

TEST(CameraFaults, AppearanceFollowerStopsOnEachFaultAndArrives) {
  const sim::Scenario scenario = sim::LoadScenario("office_aliasing");
  EigenspaceRunOptions o = EigenspaceEntryOptions({"office_aliasing", "on-route"}, 1);
  o.camera_faults = Schedule();
  std::vector<Frame> frames;
  const EigenspaceRun run =
      RunEigenspaceFollow(scenario, o, [&](const navigation::FollowerStep& s, const Pose2&) {
        frames.push_back({s.command, s.reason});
      });
  CheckFaultHandling(frames, 1.0 / scenario.camera.rate_hz);
  EXPECT_TRUE(run.success) << run.status;
  EXPECT_FALSE(run.collided);
}

}  // namespace
}  // namespace mapless::eval
