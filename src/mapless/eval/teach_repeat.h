// Closed-loop teach & repeat on the simulator, as in Section VII of Kassir et al.: teach a route by
// driving the scenario's taught path (scripted driver, clean), then repeat it from the repeat start
// (perturbed) with motion noise and image noise, the robot driven by the repeat session alone.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "mapless/navigation/repeat.h"
#include "mapless/navigation/teach.h"
#include "mapless/robot/loop.h"
#include "mapless/robot/sim_link.h"
#include "mapless/sim/camera_faults.h"
#include "mapless/sim/scenario.h"
#include "mapless/sim/simulation.h"

namespace mapless::eval {

struct TaughtRoute {
  std::shared_ptr<route::Route> route;
  std::vector<Pose2> path;  // ground-truth poses of the teach drive, one per frame
  double duration_s = 0.0;
};

// Teaches the scenario's route (no noise). `on_keyframe` may store each keyframe as it is made.
TaughtRoute TeachOnSimulator(const sim::Scenario& scenario, const navigation::TeachOptions& options,
                             const std::function<void(const route::Keyframe&)>& on_keyframe = {});

struct RepeatRunOptions {
  navigation::RepeatOptions repeat;
  double motion_noise_frac = 0.1;     // of the commanded translation and rotation
  double image_noise_sigma = 2.0;     // grey levels
  double start_offset_m = 0.1;        // uniform in +-, x and y
  double start_offset_deg = 3.0;      // uniform in +-
  double timeout_factor = 3.0;        // of the taught duration
  double max_repeat_speed_mps = 0.2;  // suites: repeat at the teach speed, at most this
  double success_radius_m = 0.5;      // final pose within this of the taught end
  // A stop that does not clear (an obstacle that stays, ground that cannot be checked) ends the
  // run after this long, as a robot file's safety.max_blocked_s does on a robot (0: never).
  double max_blocked_s = 60.0;
  std::vector<sim::CameraFaultWindow> camera_faults;  // hardening tests (sim/camera_faults.h)
  std::uint64_t seed = 1;
  robot::LinkWrapper wrap_link;  // between the loop and the simulator (a recording)
  void Validate() const;
};

struct RepeatRun {
  bool success = false;    // completed, no collision, in time, and near the taught end
  bool completed = false;  // passed the last keyframe
  bool collided = false;
  double final_error_m = 0.0;
  double lateral_rms_m = 0.0;  // RMS distance of the repeated poses to the taught path
  double duration_s = 0.0;
  std::string status;
  std::vector<Pose2> path;  // ground-truth poses of the repeat, one per frame
  std::vector<navigation::RepeatStep> steps;
  // With repeat.learn: the views learned and the view each keyframe was steered by, for
  // navigation::ApplyVisit.
  std::vector<navigation::LearnedView> learned;
  std::vector<int> used_views;
};

// Called once per frame with the robot's true pose and the decision (for logs and pictures).
using RepeatObserver =
    std::function<void(const Pose2&, const cv::Mat&, const navigation::RepeatStep&)>;

// The world, camera, robot, start pose and simulation seed of a run: the same for a run driven
// directly (RepeatOnSimulator) and one served to another process (`mapless sim serve --like`).
struct SimSetup {
  sim::World world;
  sim::CameraSpec camera;
  sim::RobotOptions robot;
  Pose2 start;
  std::uint64_t seed = 1;
};
SimSetup RepeatSimSetup(const sim::Scenario& scenario, const RepeatRunOptions& options);

RepeatRun RepeatOnSimulator(const sim::Scenario& scenario, const TaughtRoute& taught,
                            const RepeatRunOptions& options, const RepeatObserver& observer = {});

// Repeat speed for a scenario: its teach speed, capped at `cap_mps`, but never below half of it
// (a repeat must end within 3x the taught duration).
double RepeatSpeedFor(const sim::Scenario& scenario, double cap_mps);

// Why a closed-loop run on the simulator must end now (robot/sim_link.h).
using robot::SimulationStop;

// The loop of a run on the simulator: no limits but the time a stop may last.
robot::LoopOptions BlockedLoop(double max_blocked_s);

// Distance from a point to a polyline (the taught path).
double DistanceToPath(const std::vector<Pose2>& path, double x_m, double y_m);

}  // namespace mapless::eval
