// The visual-potential experiments of Ohnishi & Imiya (Section 5) on the simulator: corridor
// centring under image noise and motion noise (Fig. 20-26), navigation to destinations through an
// obstacle field (Fig. 32), homing (Fig. 38-40) and the inclusion measures of Table 1.
#pragma once

#include <Eigen/Core>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "mapless/eval/suite.h"
#include "mapless/eval/teach_repeat.h"
#include "mapless/navigation/potential.h"
#include "mapless/robot/link.h"
#include "mapless/sim/camera_faults.h"
#include "mapless/sim/scenario.h"

namespace mapless::eval {

// Calibrates the pure planar flows on the simulator as the paper does on the robot: from the
// scenario's teach start, drive straight at T_m for `frames` frames, then turn in place at R_m
// (clean images, no motion noise).
navigation::PlanarFlowCalibration CalibrateOnSimulator(const sim::Scenario& scenario,
                                                       const navigation::PotentialNavOptions& nav,
                                                       int frames = 6);

struct PotentialRunOptions {
  navigation::PotentialNavOptions nav;
  double motion_noise_frac = 0.0;  // of T and R, per command (the paper: 0.2)
  double invert_fraction = 0.0;    // image noise: fraction of pixels inverted (the paper: 0.2)
  double image_noise_sigma = 0.0;  // Gaussian image noise, grey levels
  double start_lateral_m = 0.0;    // start this far left of the scenario's teach start
  // A destination in world coordinates (the robot is told it relative to its start, and its
  // odometry starts there). Without one, corridor centring: the run ends when the robot passes
  // the end of the scenario's taught path.
  std::optional<Eigen::Vector2d> destination;
  bool homing = false;            // return to the start after the destination
  double timeout_factor = 3.0;    // of the path length at T_m (destination and back for homing)
  double success_radius_m = 0.3;  // final distance to the goal (the issue: 0.3 m)
  // A stop that does not clear (an obstacle that stays, ground that cannot be checked) ends the
  // run after this long, as a robot file's safety.max_blocked_s does on a robot (0: never).
  double max_blocked_s = 60.0;
  std::vector<sim::CameraFaultWindow> camera_faults;  // hardening tests (sim/camera_faults.h)
  std::uint64_t seed = 1;
  robot::LinkWrapper wrap_link;  // between the loop and the simulator (a recording)
  void Validate() const;
};

struct PotentialRun {
  bool success = false;  // reached (or passed the corridor's end), no collision, within radius
  bool reached = false;
  bool collided = false;
  double final_error_m = 0.0;  // to the goal (the start when homing); 0 in corridor mode
  double duration_s = 0.0;
  int no_plane_frames = 0;  // frames on which the dominant plane was lost
  std::string status;
  std::vector<Pose2> path;  // ground truth, one per frame
};

// The simulated robot of a run (see eval::SimSetup): the same for RunPotential and `mapless sim
// serve --like navigate`.
SimSetup PotentialSimSetup(const sim::Scenario& scenario, const PotentialRunOptions& options);

using PotentialObserver =
    std::function<void(const Pose2&, const cv::Mat&, const navigation::PotentialStep&)>;

PotentialRun RunPotential(const sim::Scenario& scenario,
                          const navigation::PlanarFlowCalibration& calibration,
                          const PotentialRunOptions& options,
                          const PotentialObserver& observer = {});

// Signed distance from a point to a polyline (positive to the left of its direction).
double SignedDistanceToPath(const std::vector<Pose2>& path, double x_m, double y_m);

// The paper's corridor-centring figure: the standard deviation, along the time axis, of the
// difference between a noisy and the clean trajectory (the noisy pose's signed distance to the
// clean path, over the frames both runs have).
double TrajectoryDeviationStd(const std::vector<Pose2>& clean, const std::vector<Pose2>& noisy);

// Table 1: the mean inclusion measures P(D_l ⊂ D_l+1), l = 0..2, of the hierarchical dominant
// planes (the paper's dense pyramidal LK, layers 0-3) along the scenario's taught path, driven at
// `speed_mps`. The paper's sequences move a few pixels per frame; the dense LK with 4 layers
// cannot follow the 10-30 px per frame of the floor at 0.3 m/s, so the drive is slow.
struct InclusionResult {
  std::string scenario;
  int pairs = 0;                  // frame pairs looked at
  int frames = 0;                 // of those, pairs with a plane in every layer (the average's)
  std::vector<double> inclusion;  // mean P(D_l ⊂ D_l+1)
};
InclusionResult InclusionOnSimulator(const sim::Scenario& scenario,
                                     const ground::DominantPlaneOptions& plane, int max_pairs = 60,
                                     double speed_mps = 0.05);

// One line of the potential suite.
struct PotentialEntry {
  std::string scenario;
  std::string experiment;  // image-noise, motion-noise, destination-N, homing
};
std::vector<PotentialEntry> PotentialSuiteEntries();

// The suites' common fields (controller "potential"; final error to the goal, 0 in the corridor;
// lateral_rms_m: RMS distance to the clean run's path in the corridor, else 0), and:
struct PotentialEntryResult : EntryResult {
  std::string experiment;
  double deviation_std_m = 0.0;  // corridor: mean over runs of TrajectoryDeviationStd
  double deviation_std_m_max = 0.0;
  std::vector<double> deviations_m;  // corridor: each run's TrajectoryDeviationStd
};

// Runs `runs` noisy runs of an entry with seeds seed, seed + 1, ... (and, for the corridor, one
// clean run to compare with).
// `first_run` (if set) observes every frame of the first seeded run (for reports).
PotentialEntryResult RunPotentialEntry(const PotentialEntry& entry, int runs, std::uint64_t seed,
                                       const navigation::PotentialNavOptions& nav,
                                       const PotentialObserver& first_run = {});

}  // namespace mapless::eval
