// The scripted driver of the teach phase: it drives the taught path on ground truth as a person
// would with a joystick. Straight legs are followed by pure pursuit (a look-ahead point on the
// polyline), the robot slows down before the end of a leg, turns in place first when the path
// starts behind it, and `rotate` steps turn in place by the given angle.
#pragma once

#include <vector>

#include "mapless/core/pose.h"
#include "mapless/sim/scenario.h"

namespace mapless::sim {

struct DriverOptions {
  double lookahead_m = 0.35;             // pure-pursuit look-ahead distance
  double goal_tolerance_m = 0.03;        // a leg ends within this distance of its last point
  double rotate_tolerance_rad = 0.01;    // a rotation ends within this heading error
  double rotate_speed_radps = 0.6;       // turn rate for rotations in place
  double turn_in_place_above_rad = 1.2;  // heading error above which the robot turns in place
  double decel_mps2 = 0.4;               // planned deceleration before the end of a leg
  void Validate() const;
};

class ScriptedDriver {
 public:
  ScriptedDriver(const Pose2& start, const std::vector<PathStep>& path, double default_speed_mps,
                 DriverOptions options = {});

  // The command for the current ground-truth pose; zero once the path is done.
  Twist2 Update(const Pose2& pose);
  bool done() const { return leg_ >= legs_.size(); }

 private:
  struct Leg {
    bool rotate = false;
    std::vector<Eigen::Vector2d> points;  // polyline (first = where the leg starts)
    std::vector<double> speeds;           // speed on each segment
    double rotate_rad = 0.0;
  };
  Twist2 FollowPolyline(const Pose2& pose);
  Twist2 Rotate(const Pose2& pose);

  DriverOptions options_;
  std::vector<Leg> legs_;
  std::size_t leg_ = 0;
  double progress_m_ = 0.0;  // arc length reached along the current polyline
  bool leg_started_ = false;
  double rotate_target_rad_ = 0.0;
  bool aligning_ = false;
};

}  // namespace mapless::sim
