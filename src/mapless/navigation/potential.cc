#include "mapless/navigation/potential.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "mapless/core/check.h"

namespace mapless::navigation {
namespace {

cv::Mat Grey(const cv::Mat& image) {
  MAPLESS_CHECK(
      !image.empty() && image.depth() == CV_8U && (image.channels() == 1 || image.channels() == 3),
      "PotentialNavigator: expected a non-empty 8-bit grey or BGR image");
  if (image.channels() == 1) return image.clone();
  cv::Mat grey;
  cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  return grey;
}

double MeanMagnitude(const cv::Mat& field) {
  std::vector<cv::Mat> c;
  cv::split(field, c);
  cv::Mat mag;
  cv::magnitude(c[0], c[1], mag);
  return cv::mean(mag)[0];
}

}  // namespace

cv::Mat CalibratePlanarModel(const std::vector<cv::Mat>& frames, const flow::FlowOptions& flow,
                             const ground::DominantPlaneOptions& plane) {
  MAPLESS_CHECK(frames.size() >= 2,
                "planar-flow calibration needs at least two frames, got " << frames.size());
  cv::Mat sum = cv::Mat::zeros(3, 3, CV_64F);
  int count = 0;
  flow::FlowEstimator estimator(flow);
  for (std::size_t i = 1; i < frames.size(); ++i) {
    const ground::DominantPlane p =
        ground::DetectDominantPlane(estimator.Compute(Grey(frames[i - 1]), Grey(frames[i])), plane);
    if (!p.found || std::abs(p.model.at<double>(2, 2)) < 1e-12) continue;
    sum += p.model / p.model.at<double>(2, 2);
    ++count;
  }
  MAPLESS_CHECK(count > 0, "planar-flow calibration: no dominant plane in any of the "
                               << frames.size() - 1 << " frame pairs (is the ground in view?)");
  return sum / count;
}

ground::DominantPlaneOptions DefaultPlaneOptions() {
  ground::DominantPlaneOptions o;
  o.epsilon_px = 0.5;
  o.epsilon_relative = 0.15;
  o.fit_bottom_fraction = 0.5;
  o.sample_step_px = 12;
  o.max_iterations = 1000;
  return o;
}

control::VisualPotentialOptions DefaultPotentialOptions() {
  control::VisualPotentialOptions o;
  o.repulsion_gain = 2.0;
  o.work_width_px = 40;  // the blur (sigma: half the image) on a 40-column map
  return o;
}

void PotentialNavOptions::Validate() const {
  flow.Validate();
  plane.Validate();
  potential.Validate();
  camera.Validate();
  MAPLESS_CHECK(arrive_radius_m > 0.0, "PotentialNavOptions.arrive_radius_m must be > 0");
  MAPLESS_CHECK(approach_radius_m >= 0.0, "PotentialNavOptions.approach_radius_m must be >= 0");
  MAPLESS_CHECK(creep_fraction > 0.0 && creep_fraction <= 1.0,
                "PotentialNavOptions.creep_fraction = " << creep_fraction << "; must be in (0, 1]");
  MAPLESS_CHECK(min_motion_m >= 0.0, "PotentialNavOptions.min_motion_m must be >= 0");
  MAPLESS_CHECK(
      search_step_rad > 0.0 && search_step_rad <= kPi,
      "PotentialNavOptions.search_step_rad = " << search_step_rad << "; must be in (0, pi]");
  MAPLESS_CHECK(search_rate_fraction > 0.0 && search_rate_fraction <= 1.0,
                "PotentialNavOptions.search_rate_fraction must be in (0, 1]");
  MAPLESS_CHECK(max_search_steps >= 1, "PotentialNavOptions.max_search_steps must be >= 1");
  MAPLESS_CHECK(ground_check_tolerance >= 0.0,
                "PotentialNavOptions.ground_check_tolerance must be >= 0");
  MAPLESS_CHECK(escape_distance_m >= 0.0, "PotentialNavOptions.escape_distance_m must be >= 0");
  MAPLESS_CHECK(min_free_ahead >= 0.0 && min_free_ahead <= 1.0,
                "PotentialNavOptions.min_free_ahead must be in [0, 1]");
  MAPLESS_CHECK(ahead_rows > 0.0 && ahead_rows <= 1.0 && ahead_cols > 0.0 && ahead_cols <= 1.0,
                "PotentialNavOptions.ahead_rows and ahead_cols must be in (0, 1]");
  MAPLESS_CHECK(plane_scale > 0.0 && plane_scale <= 1.0,
                "PotentialNavOptions.plane_scale = " << plane_scale << "; must be in (0, 1]");
  MAPLESS_CHECK(potential_width_px >= 16, "PotentialNavOptions.potential_width_px = "
                                              << potential_width_px << "; must be >= 16");
  MAPLESS_CHECK(plane_noise_fraction >= 0.0 && plane_noise_fraction <= 1.0,
                "PotentialNavOptions.plane_noise_fraction must be in [0, 1]");
  MAPLESS_CHECK(force_filter > 0.0 && force_filter <= 1.0,
                "PotentialNavOptions.force_filter = " << force_filter << "; must be in (0, 1]");
  MAPLESS_CHECK(misses_before_search >= 1, "PotentialNavOptions.misses_before_search must be >= 1");
}

const char* PotentialStatusName(PotentialStatus s) {
  switch (s) {
    case PotentialStatus::kDriving:
      return "driving";
    case PotentialStatus::kLooking:
      return "looking";
    case PotentialStatus::kSearching:
      return "searching";
    case PotentialStatus::kTurningAround:
      return "turning_around";
    case PotentialStatus::kArrived:
      return "arrived";
    case PotentialStatus::kAborted:
      return "aborted";
    case PotentialStatus::kCameraFault:
      return "camera_fault";
  }
  return "?";
}

PotentialNavigator::PotentialNavigator(PlanarFlowCalibration calibration,
                                       PotentialNavOptions options)
    : calibration_(std::move(calibration)),
      options_(std::move(options)),
      flow_(options_.flow),
      noise_(options_.noise_seed) {
  calibration_.Validate();
  options_.Validate();
  camera_ = CameraMonitor(options_.camera);
  const cv::Size size(calibration_.width, calibration_.height);
  translational_flow_ = ground::PlanarFlow(calibration_.translational, size);
  rotational_flow_ = ground::PlanarFlow(calibration_.rotational, size);
  flow_scale_ = MeanMagnitude(translational_flow_);
  MAPLESS_CHECK(flow_scale_ > 1e-3,
                "PlanarFlowCalibration.translational: the calibrated "
                "forward flow is zero (did the robot move?)");
  translational_flow_ /= flow_scale_;
  // The rotational field keeps its size relative to the translational one per unit of speed:
  // Eq. 13 mixes them as unit motions, so normalise it to the same mean magnitude.
  rotational_flow_ /= MeanMagnitude(rotational_flow_);
  const int w = std::min(options_.potential_width_px, calibration_.width);
  work_size_ = cv::Size(
      w, std::max(1, static_cast<int>(std::lround(static_cast<double>(calibration_.height) * w /
                                                  calibration_.width))));
  cv::resize(translational_flow_, translational_flow_, work_size_, 0, 0, cv::INTER_AREA);
  cv::resize(rotational_flow_, rotational_flow_, work_size_, 0, 0, cv::INTER_AREA);
}

void PotentialNavigator::SetDestination(const Eigen::Vector2d& destination) {
  destination_ = destination;
}

double PotentialNavigator::GroundMismatch(const cv::Mat& model, const Pose2& motion) const {
  // The ground's flow for this frame's motion, from the calibration: the forward and turning
  // flows scaled by how far the robot went and turned (odometry) relative to the calibration
  // drive. The fitted plane's flow (in plane_scale pixels) is compared with it on a coarse grid.
  const double a = motion.x_m / (calibration_.speed_mps * calibration_.period_s);
  const double b = motion.theta_rad / (calibration_.omega_radps * calibration_.period_s);
  const double s = options_.plane_scale;
  const auto* m = model.ptr<double>();
  const auto* t = calibration_.translational.ptr<double>();
  const auto* r = calibration_.rotational.ptr<double>();
  auto flow_at = [](const double* h, double x, double y) {
    const double w = h[6] * x + h[7] * y + h[8];
    const double k = std::abs(w) > 1e-12 ? 1.0 / w : 0.0;
    return cv::Vec2d((h[0] * x + h[1] * y + h[2]) * k - x, (h[3] * x + h[4] * y + h[5]) * k - y);
  };
  double diff = 0.0;
  double norm = 0.0;
  constexpr int kGrid = 12;
  for (int j = 0; j < kGrid; ++j) {
    for (int i = 0; i < kGrid; ++i) {
      const double x = (i + 0.5) * calibration_.width / kGrid;
      const double y = (j + 0.5) * calibration_.height / kGrid;
      const cv::Vec2d predicted = a * flow_at(t, x, y) + b * flow_at(r, x, y);
      const cv::Vec2d fitted = flow_at(m, x * s, y * s) / s;
      diff += cv::norm(fitted - predicted);
      norm += cv::norm(predicted);
    }
  }
  return norm > 1e-9 ? diff / norm : 0.0;
}

double PotentialNavigator::AvoidanceDirection(const Pose2& odometry, double theta_rad) {
  const bool recent =
      have_avoided_ && std::hypot(odometry.x_m - avoided_at_.x_m, odometry.y_m - avoided_at_.y_m) <
                           options_.escape_distance_m;
  if (!recent) avoid_direction_ = theta_rad < 0.0 ? -1.0 : 1.0;
  have_avoided_ = true;
  avoided_at_ = odometry;
  return avoid_direction_;
}

PotentialStep PotentialNavigator::Search(PotentialStep step, const Pose2& odometry,
                                         const std::string& why) {
  if (status_ != PotentialStatus::kSearching) {
    ++search_steps_;
    if (search_steps_ > options_.max_search_steps) {
      status_ = PotentialStatus::kAborted;
      step.status = status_;
      step.reason = why + "; no free ground after " + std::to_string(options_.max_search_steps) +
                    " turns: stopped";
      step.command = {};
      return step;
    }
    status_ = PotentialStatus::kSearching;
    // Turn towards the side where the ground was last seen (the last force's side), unless the
    // robot turned away from something within the last escape_distance_m: then keep that side.
    turn_direction_ = AvoidanceDirection(odometry, last_theta_rad_);
    turn_target_rad_ = odometry.theta_rad + turn_direction_ * options_.search_step_rad;
  }
  step.status = status_;
  step.reason = why + ": stopped, turning in place to look for free ground";
  step.command = {
      0.0, turn_direction_ * options_.search_rate_fraction * options_.potential.max_rotation_radps};
  return step;
}

PotentialStep PotentialNavigator::Update(const cv::Mat& image, const Pose2& odometry) {
  PotentialStep step;
  const CameraCheck camera = camera_.Check(image, last_command_);
  if (finished()) {
    step.status = status_;
    step.leg = leg_;
    step.reason = status_ == PotentialStatus::kArrived ? "destination reached" : "aborted";
  } else if (!camera.usable()) {
    step.status = PotentialStatus::kCameraFault;
    step.leg = leg_;
    step.reason = camera.reason;
  } else {
    step = Decide(image, odometry);
  }
  last_command_ = step.command;
  return step;
}

// Ohnishi & Imiya's navigation, one frame, in the stages below: the destination (Section 5.4's
// turn round at it), turning in place, the motion the plane needs, the dominant plane of the flow
// (Section 3), and the potential's force and command (Section 4, Eq. 11-17).
PotentialStep PotentialNavigator::Decide(const cv::Mat& image, const Pose2& odometry) {
  MAPLESS_CHECK(image.cols == calibration_.width && image.rows == calibration_.height,
                "PotentialNavigator: image is " << image.cols << "x" << image.rows
                                                << ", the calibration is for " << calibration_.width
                                                << "x" << calibration_.height);
  PotentialStep step;
  step.leg = leg_;
  const cv::Mat grey = Grey(image);
  if (!start_) start_ = Eigen::Vector2d(odometry.x_m, odometry.y_m);
  UpdateGoal(odometry, &step);
  if (finished()) {
    step.status = status_;
    step.reason = status_ == PotentialStatus::kArrived ? "destination reached" : "aborted";
    previous_ = grey;
    previous_odometry_ = odometry;
    return step;
  }
  step.leg = leg_;
  if (TurnInPlace(grey, odometry, &step) || WaitForMotion(grey, odometry, &step)) return step;
  ground::DominantPlane plane;
  cv::Mat flow;
  if (!FindGround(grey, odometry, &plane, &flow, &step)) return step;
  Steer(grey, odometry, plane, flow, &step);
  status_ = PotentialStatus::kDriving;
  step.status = status_;
  return step;
}

void PotentialNavigator::UpdateGoal(const Pose2& odometry, PotentialStep* step) {
  if (!destination_) return;
  const Eigen::Vector2d to = *destination_ - Eigen::Vector2d(odometry.x_m, odometry.y_m);
  step->theta_d_rad = WrapAngle(std::atan2(to.y(), to.x()) - odometry.theta_rad);
  goal_distance_m_ = to.norm();
  if (status_ != PotentialStatus::kTurningAround && to.norm() <= options_.arrive_radius_m) {
    if (options_.homing && leg_ == 0) {
      // Section 5.4: turn 180 degrees, swap start and destination, navigate back.
      leg_ = 1;
      std::swap(*destination_, *start_);
      status_ = PotentialStatus::kTurningAround;
      turn_direction_ = 1.0;
      turn_target_rad_ = odometry.theta_rad + kPi;
    } else {
      status_ = PotentialStatus::kArrived;
    }
  }
}

bool PotentialNavigator::TurnInPlace(const cv::Mat& grey, const Pose2& odometry,
                                     PotentialStep* step) {
  const double turn_rate = options_.search_rate_fraction * options_.potential.max_rotation_radps;
  // Turning in place (searching, or turning round at the destination) until the target heading.
  if (status_ == PotentialStatus::kSearching || status_ == PotentialStatus::kTurningAround) {
    const double left = turn_direction_ * WrapAngle(turn_target_rad_ - odometry.theta_rad);
    if (left > 0.02) {
      step->status = status_;
      step->reason = status_ == PotentialStatus::kSearching
                         ? "no ground plane: turning in place to look for free ground"
                         : "destination reached: turning round to go home";
      // Slow down near the target so the turn does not overshoot by a frame.
      const double period = std::max(calibration_.period_s, 1e-3);
      const double rate = std::min(turn_rate, left / period);
      step->command = {0.0, turn_direction_ * rate};
      previous_ = grey;
      previous_odometry_ = odometry;
      return true;
    }
    if (status_ == PotentialStatus::kTurningAround) search_steps_ = 0;
    misses_ = 0;
    last_plane_fraction_ = 1.0;  // a new view: one creep to look at it
    last_plane_found_ = true;
    status_ = PotentialStatus::kLooking;
  }

  return false;
}

bool PotentialNavigator::WaitForMotion(const cv::Mat& grey, const Pose2& odometry,
                                       PotentialStep* step) {
  const double vmax = options_.potential.max_translation_mps;
  // The plane is observable only when the camera translated between the two frames.
  const double moved =
      std::hypot(odometry.x_m - previous_odometry_.x_m, odometry.y_m - previous_odometry_.y_m);
  if (!previous_.empty() && moved < options_.min_motion_m &&
      last_plane_fraction_ < options_.full_speed_plane_fraction) {
    // Stopped with an obstacle in view (a force pointing back, a potential minimum): creeping on
    // would drive blind towards it, so turn away first.
    previous_ = grey;
    previous_odometry_ = odometry;
    *step = Search(*step, odometry,
                   last_plane_found_ ? "stopped with an obstacle ahead" : "no ground plane");
    return true;
  }
  if (previous_.empty() || moved < options_.min_motion_m) {
    status_ = PotentialStatus::kLooking;
    step->status = status_;
    step->reason = "creeping forward one frame to see the ground move";
    step->command = {options_.creep_fraction * vmax, 0.0};
    previous_ = grey;
    previous_odometry_ = odometry;
    return true;
  }

  return false;
}

bool PotentialNavigator::FindGround(const cv::Mat& grey, const Pose2& odometry,
                                    ground::DominantPlane* found, cv::Mat* flow_out,
                                    PotentialStep* step) {
  cv::Mat flow = flow_.Compute(previous_, grey);
  const Pose2 motion = previous_odometry_.Inverse() * odometry;  // this frame's, by odometry
  previous_ = grey;
  previous_odometry_ = odometry;
  ground::DominantPlaneOptions plane_options = options_.plane;
  if (options_.plane_scale < 1.0) {
    // The plane on a coarser flow field: the field is averaged down and its vectors (and the
    // tolerance, and the RANSAC grid) are scaled to the coarse pixels.
    cv::resize(flow, flow, cv::Size(), options_.plane_scale, options_.plane_scale, cv::INTER_AREA);
    flow *= options_.plane_scale;
    plane_options.epsilon_px *= options_.plane_scale;
    plane_options.sample_step_px = std::max(
        1, static_cast<int>(std::lround(plane_options.sample_step_px * options_.plane_scale)));
  }
  ground::DominantPlane plane = ground::DetectDominantPlane(flow, plane_options);
  bool not_ground = false;
  if (plane.found && options_.ground_check_tolerance > 0.0) {
    step->ground_mismatch = GroundMismatch(plane.model, motion);
    not_ground = step->ground_mismatch > options_.ground_check_tolerance;
    if (not_ground) {
      plane.found = false;
      plane.mask.setTo(0);
    }
  }
  step->plane_found = plane.found;
  step->plane_fraction = plane.roi_fraction;
  last_plane_fraction_ = plane.roi_fraction;
  last_plane_found_ = plane.found;
  step->plane_mask = plane.mask;
  if (!plane.found) {
    std::ostringstream why;
    if (not_ground) {
      why << "the dominant plane does not move like the ground (a wall or an obstacle fills the "
             "view)";
    } else {
      why << "no ground plane (" << static_cast<int>(std::lround(100.0 * plane.roi_fraction))
          << "% of the view)";
    }
    if (++misses_ >= options_.misses_before_search) {
      *step = Search(*step, odometry, why.str());
      return false;
    }
    // Stop and look again (the next frame, standing, cannot see: it creeps one frame).
    status_ = PotentialStatus::kLooking;
    step->status = status_;
    step->reason = why.str() + ": stopped to look again";
    step->command = {};
    return false;
  }
  search_steps_ = 0;
  misses_ = 0;

  *found = plane;
  *flow_out = flow;
  return true;
}

void PotentialNavigator::Steer(const cv::Mat& grey, const Pose2& odometry,
                               const ground::DominantPlane& plane, const cv::Mat& flow,
                               PotentialStep* step) {
  const double vmax = options_.potential.max_translation_mps;
  if (options_.min_free_ahead > 0.0) {
    // The safety window: the ground just in front of the robot (the bottom-centre of the image),
    // measured on the detected map (before any experimental noise below).
    const cv::Mat& m = plane.mask;
    const int h = std::max(1, static_cast<int>(std::lround(m.rows * options_.ahead_rows)));
    const int w = std::max(1, static_cast<int>(std::lround(m.cols * options_.ahead_cols)));
    const cv::Rect ahead((m.cols - w) / 2, m.rows - h, w, h);
    step->free_ahead = static_cast<double>(cv::countNonZero(m(ahead))) / ahead.area();
  }
  // The map the potential sees: the detected one, or (robustness experiments) a copy with
  // inverted pixels, so step->plane_mask stays the detection.
  cv::Mat map = plane.mask;
  if (options_.plane_noise_fraction > 0.0) {
    map = plane.mask.clone();
    for (int y = 0; y < map.rows; ++y) {
      uchar* d = map.ptr<uchar>(y);
      for (int x = 0; x < map.cols; ++x)
        if (noise_.Uniform() < options_.plane_noise_fraction) d[x] = 255 - d[x];
    }
  }
  // The potential is averaged over the image (Eq. 15), so it is computed on a coarse grid of
  // potential_width_px columns: the same mean, a sixteenth of the work at 320x240.
  cv::Mat d;
  cv::resize(map, d, work_size_, 0, 0, cv::INTER_NEAREST);
  // Attraction: the desired flow towards the destination (Eq. 13; theta_d = 0 without one), or
  // the measured planar flow (Eq. 11) when asked; in units of the calibrated forward flow.
  cv::Mat attraction;
  if (!destination_ && options_.follow_planar_flow) {
    // The model is in the plane's (scaled) pixels; back to image pixels per frame.
    cv::resize(ground::PlanarFlow(plane.model, flow.size()) / (flow_scale_ * options_.plane_scale),
               attraction, work_size_, 0, 0, cv::INTER_AREA);
  } else {
    attraction = control::DesiredFlow(translational_flow_, rotational_flow_, step->theta_d_rad);
  }
  control::VisualPotentialOptions potential_options = options_.potential;
  potential_options.work_width_px = std::min(d.cols, options_.potential.work_width_px);
  // g per pixel of the full image (the gain is tuned in those units).
  const cv::Mat repulsion =
      control::RepulsionField(d, potential_options) * (static_cast<double>(d.cols) / grey.cols);
  const cv::Mat potential = control::PotentialField(d, repulsion, attraction, options_.potential);
  const cv::Vec2d force = control::ControlForce(potential);
  filtered_force_ =
      have_force_ ? options_.force_filter * force + (1.0 - options_.force_filter) * filtered_force_
                  : force;
  have_force_ = true;
  step->force = filtered_force_;
  const control::PotentialCommand c = control::CommandFromForce(step->force, options_.potential);
  step->theta_rad = c.theta_rad;
  last_theta_rad_ = c.theta_rad;
  step->command = c.twist;
  if (!options_.allow_reverse && step->command.v_mps < 0.0) {
    // A force pointing backwards: a robot that does not reverse turns in place towards it at the
    // full rate (Eq. 17 would give R -> 0 as the force points straight back).
    step->command.v_mps = 0.0;
    step->command.omega_radps =
        (c.theta_rad >= 0.0 ? 1.0 : -1.0) * options_.potential.max_rotation_radps;
  }
  if (step->free_ahead < options_.min_free_ahead) {
    // An obstacle close in front: no forward motion; turn in place towards the force's side.
    step->command.v_mps = 0.0;
    step->command.omega_radps =
        AvoidanceDirection(odometry, c.theta_rad) * options_.potential.max_rotation_radps;
    step->reason = "obstacle just ahead: turning in place";
  }
  if (options_.full_speed_plane_fraction > options_.plane.min_plane_fraction) {
    const double lo = options_.plane.min_plane_fraction;
    step->command.v_mps *=
        std::clamp((plane.roi_fraction - lo) / (options_.full_speed_plane_fraction - lo), 0.0, 1.0);
  }
  if (goal_distance_m_ >= 0.0 && goal_distance_m_ < options_.approach_radius_m) {
    const double cap = std::max(options_.creep_fraction * vmax,
                                vmax * goal_distance_m_ / options_.approach_radius_m);
    step->command.v_mps = std::min(step->command.v_mps, cap);
  }
}

}  // namespace mapless::navigation
