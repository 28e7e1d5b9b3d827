// Navigation by the visual potential (Ohnishi & Imiya, Sections 4-5): from consecutive camera
// images, dense optical flow -> dominant plane (free ground) -> potential field -> (T, R).
//
// Three uses, one loop (Fig. 14):
//   - corridor centring: no destination; the attraction is the calibrated forward flow (Eq. 13 with
//     theta_d = 0), or, as an option, the measured planar flow of Eq. 11 (see
//     PotentialNavOptions::follow_planar_flow for why that is not the default);
//   - navigation to a destination: the attraction is the desired flow mixed from the calibrated
//     pure translational and rotational planar flows by the destination angle theta_d (Eq. 13-14),
//     theta_d from the robot's odometry (Section 5.3.2, Eq. 27);
//   - homing (Section 5.4): at the destination, turn 180 degrees, swap start and destination, and
//     navigate back.
//
// Safety: the plane is only observable while the robot translates (a standing or purely rotating
// camera moves every scene point by the same homography). When the dominant plane is lost (a wall
// fills the view), the robot stops, turns in place by a fixed step, creeps forward one frame to
// look again, and reports why; it never drives on into what it cannot see.
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "mapless/control/visual_potential.h"
#include "mapless/core/pose.h"
#include "mapless/core/rng.h"
#include "mapless/flow/flow.h"
#include "mapless/ground/dominant_plane.h"
#include "mapless/io/planar_flow_calibration.h"
#include "mapless/navigation/camera_check.h"

namespace mapless::navigation {

// The planar-flow calibration (Section 4.3) and its file: io/planar_flow_calibration.h.
using PlanarFlowCalibration = io::PlanarFlowCalibration;
using io::CalibrationFromYaml;
using io::CalibrationToYaml;

// The mean ground homography over consecutive pairs of `frames` (taken while driving at constant
// velocity): each pair's flow is fitted by RANSAC and the models (normalised to h33 = 1) averaged.
// Throws InputError when fewer than two frames are given or no pair shows a plane.
cv::Mat CalibratePlanarModel(const std::vector<cv::Mat>& frames, const flow::FlowOptions& flow,
                             const ground::DominantPlaneOptions& plane);

ground::DominantPlaneOptions DefaultPlaneOptions();
inline flow::FlowOptions MediumFlow() {
  flow::FlowOptions o;
  o.method = flow::FlowMethod::kDisMedium;
  // The flow 160 px wide whatever the camera: DIS medium's own level at 320x240 (the frames the
  // defaults were chosen on), and at 640x480 the same work instead of 4x (issue 44).
  o.dis_max_flow_width_px = 160;
  return o;
}
control::VisualPotentialOptions DefaultPotentialOptions();

struct PotentialNavOptions {
  // DIS medium: with DIS fast the ground map's upper edge flickered from frame to frame and the
  // robot wandered +-0.1 m in the corridor (noisy-vs-clean deviation 0.05 m); with DIS medium
  // 0.010-0.015 m. A step costs 5.8 ms instead of 1.5 ms (mapless bench), well inside a 100 ms
  // control period.
  flow::FlowOptions flow = MediumFlow();
  // Tuned on the simulator (docs/flow_and_ground.md): a tolerance of 0.5 px + 15% of the planar
  // flow, RANSAC fitted on the bottom half of the image.
  ground::DominantPlaneOptions plane = DefaultPlaneOptions();
  // Repulsion gain 2 (the paper's Eq. 11 has 1: our attraction is in units of the calibrated
  // forward flow, so the balance is ours to set).
  control::VisualPotentialOptions potential = DefaultPotentialOptions();
  // The attraction is divided by the mean magnitude of the calibrated translational flow, so the
  // repulsion gain does not depend on the camera, its mount or the speed.
  // Not in the paper: the speed falls with the free ground in view, from T_m when at least this
  // fraction of the region of interest is ground to 0 at the "no plane" threshold
  // (plane.min_plane_fraction), so the robot slows as obstacles fill the view and turns tighter.
  // 0 disables it.
  double full_speed_plane_fraction = 0.9;
  // Not in the paper: a safety window. The bottom-centre of the image (the lowest ahead_rows of the
  // rows, the central ahead_cols of the columns) is the ground just in front of the robot; when
  // less than min_free_ahead of it is plane, the robot does not drive forward but turns in place
  // towards the force's side. Image fractions, so no calibration is needed. 0 disables it.
  double min_free_ahead = 0.9;
  double ahead_rows = 0.35;
  double ahead_cols = 0.5;
  // Not in the paper: the dominant plane must move like the ground. Its flow is compared with the
  // ground flow predicted for this frame's odometry from the calibration (mean |difference| over
  // mean |predicted|); above this it is a wall or an obstacle filling the view, and the frame
  // counts as "no plane". 0 disables it.
  double ground_check_tolerance = 0.5;
  // Turning away from an obstacle (the safety window, a search): within this distance of the last
  // such turn the robot keeps turning to the same side. Choosing the side afresh each time made it
  // dither left and right in front of a box corner, creeping closer at each look, until it touched.
  double escape_distance_m = 0.3;
  // The dominant plane is detected on the flow field scaled by this (0.5: 160x120 for a 320x240
  // camera): the potential only needs the map at potential_width_px columns. PotentialStep's
  // plane_mask is at this scale.
  double plane_scale = 0.5;
  int potential_width_px = 80;   // the potential field's grid (its mean is what drives)
  double arrive_radius_m = 0.1;  // the destination is reached (by odometry) within this
  // Closer than this to the destination the speed falls in proportion to the distance (down to
  // the creep speed), so the turning circle shrinks and the robot cannot orbit the goal.
  double approach_radius_m = 0.6;
  double creep_fraction = 0.25;       // of T_m: the one-frame step taken to see the ground move
  double min_motion_m = 0.004;        // less translation between frames: the plane is unobservable
  double search_step_rad = 0.6;       // no plane: turn in place by this much, then look again
  double search_rate_fraction = 0.8;  // of R_m, while searching and turning round
  int misses_before_search = 3;       // frames in a row without a plane before turning to search
                                      // (before that the robot only stops and looks again)
  int max_search_steps = 12;  // searched this often in a row without finding ground: give up
  // Not in the paper: a first-order low-pass on the control force, f <- a f_new + (1 - a) f
  // (a = 1: none). A single frame's mask noise then cannot jerk the robot.
  double force_filter = 0.2;
  bool allow_reverse = false;  // Eq. 17 gives T < 0 for a force pointing backwards; clamp to 0
  // Robustness experiments of Section 5.2 only: invert this fraction of the dominant-plane map's
  // pixels each frame ("an error of 20% to the detected dominant plane"), drawn from noise_seed.
  double plane_noise_fraction = 0.0;
  std::uint64_t noise_seed = 1;
  bool homing = false;  // after the destination, turn round and return to the start
  // Without a destination, attract along the measured planar flow (Eq. 11-12) instead of the
  // calibrated forward flow. Off by default: the measured flow contains the robot's own rotation,
  // and -u_hat of a left turn points left, so the turn feeds itself (on the simulator the robot
  // spins on the spot in the straight corridor).
  bool follow_planar_flow = false;
  CameraCheckOptions camera;  // camera faults: stop until the images are usable again
  void Validate() const;
};

enum class PotentialStatus {
  kDriving,        // following the potential
  kLooking,        // creeping one frame to see the ground move (start, after a turn)
  kSearching,      // no dominant plane: stopped, turning in place
  kTurningAround,  // homing: turning 180 degrees at the destination
  kArrived,        // the (last) destination is reached: stopped
  kAborted,        // no ground found after max_search_steps: stopped
  kCameraFault,    // the frame is unusable (camera_check.h): stopped until images return
};
const char* PotentialStatusName(PotentialStatus s);

struct PotentialStep {
  PotentialStatus status = PotentialStatus::kDriving;
  std::string reason;
  bool plane_found = false;
  double plane_fraction = 0.0;   // of the region of interest
  double free_ahead = 1.0;       // plane fraction of the window just ahead (see min_free_ahead)
  double ground_mismatch = 0.0;  // the plane's flow against the predicted ground flow
  double theta_d_rad = 0.0;      // destination direction relative to the heading (0 without one)
  double theta_rad = 0.0;        // direction of the control force (Eq. 16), positive to the left
  cv::Vec2d force{0.0, 0.0};     // Eq. 15
  int leg = 0;                   // 0: to the destination, 1: homing
  Twist2 command;
  cv::Mat plane_mask;  // d(x, y, t) of this frame at plane_scale (empty when no flow was computed)
};

class PotentialNavigator {
 public:
  PotentialNavigator(PlanarFlowCalibration calibration, PotentialNavOptions options);

  // The destination in the odometry frame; without one, the robot drives ahead and centres itself
  // in free space (corridor centring). Call before the first Update.
  void SetDestination(const Eigen::Vector2d& destination);

  // One control period: the camera image and the robot's odometry pose at the same time.
  // A camera fault gives kCameraFault with a zero command; the frame is otherwise ignored, so the
  // next usable frame's flow is measured against the last usable one.
  PotentialStep Update(const cv::Mat& image, const Pose2& odometry);
  bool finished() const {
    return status_ == PotentialStatus::kArrived || status_ == PotentialStatus::kAborted;
  }

 private:
  PotentialStep Decide(const cv::Mat& image, const Pose2& odometry);
  // The stages of Decide; those returning bool are true when they decided the frame (TurnInPlace,
  // WaitForMotion) or when there is ground to steer on (FindGround: false when it decided).
  void UpdateGoal(const Pose2& odometry, PotentialStep* step);
  bool TurnInPlace(const cv::Mat& grey, const Pose2& odometry, PotentialStep* step);
  bool WaitForMotion(const cv::Mat& grey, const Pose2& odometry, PotentialStep* step);
  bool FindGround(const cv::Mat& grey, const Pose2& odometry, ground::DominantPlane* plane,
                  cv::Mat* flow, PotentialStep* step);
  void Steer(const cv::Mat& grey, const Pose2& odometry, const ground::DominantPlane& plane,
             const cv::Mat& flow, PotentialStep* step);
  PotentialStep Search(PotentialStep step, const Pose2& odometry, const std::string& why);
  double GroundMismatch(const cv::Mat& model, const Pose2& motion) const;
  // +1 (left) or -1: the side of theta, or the side chosen by a turn within escape_distance_m.
  double AvoidanceDirection(const Pose2& odometry, double theta_rad);

  PlanarFlowCalibration calibration_;
  PotentialNavOptions options_;
  flow::FlowEstimator flow_;    // options_.flow, its buffers kept from frame to frame
  cv::Size work_size_;          // the potential's grid
  cv::Mat translational_flow_;  // unit-mean-magnitude fields on that grid
  cv::Mat rotational_flow_;
  double flow_scale_ = 1.0;  // mean |u_t| of the calibration, pixels per frame
  std::optional<Eigen::Vector2d> destination_;
  std::optional<Eigen::Vector2d> start_;
  int leg_ = 0;
  PotentialStatus status_ = PotentialStatus::kLooking;
  CameraMonitor camera_;
  Twist2 last_command_;
  cv::Mat previous_;
  Pose2 previous_odometry_;
  double turn_target_rad_ = 0.0;  // searching / turning around: heading to reach
  double turn_direction_ = 1.0;
  int search_steps_ = 0;
  int misses_ = 0;
  bool have_avoided_ = false;
  Pose2 avoided_at_;
  double avoid_direction_ = 1.0;
  double last_theta_rad_ = 0.0;
  double last_plane_fraction_ = 1.0;  // of the last frame with flow
  bool last_plane_found_ = true;
  double goal_distance_m_ = -1.0;  // odometry distance to the destination (< 0: none)
  Rng noise_;
  cv::Vec2d filtered_force_{0.0, 0.0};
  bool have_force_ = false;  // direction of the last force: the side where the ground was
};

}  // namespace mapless::navigation
