// A differential-drive robot on the ground plane: commanded (v, omega) subject to velocity and
// acceleration limits, integrated exactly (arcs) at a fixed step, with motion noise and a wheel
// odometry that drifts. Collisions are checked against the world's obstacles by the Simulation.
#pragma once

#include "mapless/core/pose.h"
#include "mapless/core/rng.h"

namespace mapless::sim {

struct RobotOptions {
  double radius_m = 0.2;          // footprint radius for collision checks
  double max_v_mps = 1.0;         // |v| limit
  double max_omega_radps = 2.0;   // |omega| limit
  double max_accel_mps2 = 1.5;    // |dv/dt| limit
  double max_alpha_radps2 = 6.0;  // |domega/dt| limit
  // Motion noise: each new command is executed as cmd * (1 + N(0, frac^2)), independently for
  // translation and rotation, held until the next command (the papers use 0.2).
  double motion_noise_v_frac = 0.0;
  double motion_noise_omega_frac = 0.0;
  // Odometry: measured = true * (1 + scale_error) + N(0, sigma^2) per step; drift accumulates.
  double odom_scale_error = 0.01;   // systematic wheel-radius error (fraction)
  double odom_noise_v_mps = 0.005;  // white noise on the measured speed
  double odom_noise_omega_radps = 0.005;
  void Validate() const;
};

class DiffDriveRobot {
 public:
  DiffDriveRobot(const Pose2& start, RobotOptions options, std::uint64_t seed);

  // Sets the command from the controller; motion noise for this command is drawn here.
  void SetCommand(const Twist2& command);
  // Advances by dt seconds (velocity ramps to the noisy command within the acceleration limits).
  void Step(double dt_s);

  const Pose2& pose() const { return pose_; }           // ground truth
  const Pose2& odometry() const { return odom_; }       // dead-reckoned, drifts
  const Twist2& velocity() const { return velocity_; }  // actual current velocity
  const Twist2& command() const { return command_; }
  const RobotOptions& options() const { return options_; }
  // Places the robot (ground truth and odometry) at a pose and stops it.
  void Reset(const Pose2& pose);

 private:
  RobotOptions options_;
  Rng rng_;
  Pose2 pose_;
  Pose2 odom_;
  Twist2 command_;
  Twist2 target_;  // command with this period's noise
  Twist2 velocity_;
};

}  // namespace mapless::sim
