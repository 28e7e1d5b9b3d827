#include "mapless/sim/robot.h"

#include <algorithm>
#include <cmath>

#include "mapless/core/check.h"

namespace mapless::sim {
namespace {

double Ramp(double current, double target, double max_step) {
  return current + std::clamp(target - current, -max_step, max_step);
}

}  // namespace

void RobotOptions::Validate() const {
  const auto in = [](double v, double lo, double hi) { return v >= lo && v <= hi; };
  MAPLESS_CHECK(in(radius_m, 0.01, 10.0),
                "RobotOptions.radius_m = " << radius_m << "; must be in [0.01, 10]");
  MAPLESS_CHECK(in(max_v_mps, 1e-3, 20.0),
                "RobotOptions.max_v_mps = " << max_v_mps << "; must be in [0.001, 20]");
  MAPLESS_CHECK(in(max_omega_radps, 1e-3, 20.0),
                "RobotOptions.max_omega_radps = " << max_omega_radps << "; must be in [0.001, 20]");
  MAPLESS_CHECK(in(max_accel_mps2, 1e-3, 1e6),
                "RobotOptions.max_accel_mps2 = " << max_accel_mps2 << "; must be in [0.001, 1e6]");
  MAPLESS_CHECK(
      in(max_alpha_radps2, 1e-3, 1e6),
      "RobotOptions.max_alpha_radps2 = " << max_alpha_radps2 << "; must be in [0.001, 1e6]");
  MAPLESS_CHECK(
      in(motion_noise_v_frac, 0.0, 1.0),
      "RobotOptions.motion_noise_v_frac = " << motion_noise_v_frac << "; must be in [0, 1]");
  MAPLESS_CHECK(in(motion_noise_omega_frac, 0.0, 1.0),
                "RobotOptions.motion_noise_omega_frac = " << motion_noise_omega_frac
                                                          << "; must be in [0, 1]");
  MAPLESS_CHECK(
      in(odom_scale_error, -0.5, 0.5),
      "RobotOptions.odom_scale_error = " << odom_scale_error << "; must be in [-0.5, 0.5]");
  MAPLESS_CHECK(in(odom_noise_v_mps, 0.0, 10.0) && in(odom_noise_omega_radps, 0.0, 10.0),
                "RobotOptions.odom_noise_*: must be in [0, 10]");
}

DiffDriveRobot::DiffDriveRobot(const Pose2& start, RobotOptions options, std::uint64_t seed)
    : options_(options), rng_(seed), pose_(start), odom_(start) {
  options_.Validate();
}

void DiffDriveRobot::Reset(const Pose2& pose) {
  pose_ = pose;
  odom_ = pose;
  command_ = target_ = velocity_ = Twist2{};
}

void DiffDriveRobot::SetCommand(const Twist2& command) {
  command_.v_mps = std::clamp(command.v_mps, -options_.max_v_mps, options_.max_v_mps);
  command_.omega_radps =
      std::clamp(command.omega_radps, -options_.max_omega_radps, options_.max_omega_radps);
  target_ = command_;
  if (options_.motion_noise_v_frac > 0.0) {
    target_.v_mps *= 1.0 + options_.motion_noise_v_frac * rng_.Normal();
  }
  if (options_.motion_noise_omega_frac > 0.0) {
    target_.omega_radps *= 1.0 + options_.motion_noise_omega_frac * rng_.Normal();
  }
}

void DiffDriveRobot::Step(double dt_s) {
  // Average velocity over the step under the ramp, then one exact arc.
  const Twist2 before = velocity_;
  velocity_.v_mps = Ramp(velocity_.v_mps, target_.v_mps, options_.max_accel_mps2 * dt_s);
  velocity_.omega_radps =
      Ramp(velocity_.omega_radps, target_.omega_radps, options_.max_alpha_radps2 * dt_s);
  const Twist2 mean{0.5 * (before.v_mps + velocity_.v_mps),
                    0.5 * (before.omega_radps + velocity_.omega_radps)};
  pose_ = IntegrateTwist(pose_, mean, dt_s);
  Twist2 measured = mean;
  measured.v_mps = mean.v_mps * (1.0 + options_.odom_scale_error);
  measured.omega_radps = mean.omega_radps * (1.0 + options_.odom_scale_error);
  if (options_.odom_noise_v_mps > 0.0) measured.v_mps += options_.odom_noise_v_mps * rng_.Normal();
  if (options_.odom_noise_omega_radps > 0.0) {
    measured.omega_radps += options_.odom_noise_omega_radps * rng_.Normal();
  }
  odom_ = IntegrateTwist(odom_, measured, dt_s);
}

}  // namespace mapless::sim
