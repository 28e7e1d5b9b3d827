#include "mapless/control/taught_path.h"

#include <algorithm>
#include <cmath>

#include "mapless/core/check.h"

namespace mapless::control {

void TaughtPathOptions::Validate() const {
  MAPLESS_CHECK(reached_m > 0.0, "TaughtPathOptions.reached_m = " << reached_m << "; must be > 0");
  MAPLESS_CHECK(max_distance_m >= 0.0,
                "TaughtPathOptions.max_distance_m = " << max_distance_m << "; must be >= 0");
  MAPLESS_CHECK(max_omega_radps > 0.0,
                "TaughtPathOptions.max_omega_radps = " << max_omega_radps << "; must be > 0");
  MAPLESS_CHECK(
      turn_in_place_rad > 0.0 && turn_in_place_rad <= M_PI,
      "TaughtPathOptions.turn_in_place_rad = " << turn_in_place_rad << "; must be in (0, pi]");
}

TaughtPathPursuit::TaughtPathPursuit(std::vector<Pose2> taught, const Pose2& anchor_taught,
                                     const Pose2& anchor_odometry, TaughtPathOptions options)
    : options_(options) {
  options_.Validate();
  // repeat_from_teach maps the teach's odometry frame into the repeat's.
  const Pose2 repeat_from_teach = anchor_odometry * anchor_taught.Inverse();
  taught_.reserve(taught.size());
  for (const Pose2& p : taught) taught_.push_back(repeat_from_teach * p);
}

std::optional<Twist2> TaughtPathPursuit::Command(const Pose2& now, double speed_mps) {
  if (last_) driven_m_ += now.DistanceTo(*last_);
  last_ = now;
  if (driven_m_ > options_.max_distance_m) return std::nullopt;
  const Pose2 robot_from_odom = now.Inverse();
  double x = 0.0;
  double y = 0.0;
  while (target_ < size()) {
    const Pose2& t = taught_[static_cast<std::size_t>(target_)];
    robot_from_odom.Apply(t.x_m, t.y_m, &x, &y);
    // Reached, or passed (behind the robot: the robot went by it off to one side).
    if (std::hypot(x, y) >= options_.reached_m && x > 0.0) break;
    ++target_;
  }
  if (target_ >= size()) return std::nullopt;
  Twist2 command;
  const double bearing = std::atan2(y, x);
  if (std::abs(bearing) > options_.turn_in_place_rad) {
    command.omega_radps = std::copysign(options_.max_omega_radps, bearing);
    return command;
  }
  // Pure pursuit: the arc through the target, curvature 2 y / d^2.
  const double d2 = x * x + y * y;
  command.v_mps = speed_mps;
  command.omega_radps =
      std::clamp(2.0 * speed_mps * y / d2, -options_.max_omega_radps, options_.max_omega_radps);
  return command;
}

}  // namespace mapless::control
