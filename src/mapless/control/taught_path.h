// Driving a stretch of the taught path by odometry alone (issue 21; not in the papers): where the
// keyframes' landmarks are gone (a parked car that has left), the repeat carries on along the
// poses the teach's odometry recorded at those keyframes, while it keeps trying to match the
// keyframes that follow. A pure-pursuit controller over those poses: the next pose neither
// reached nor behind the robot is the target; a target far off the heading is turned to in
// place first.
//
// The taught poses are in the teach's odometry frame, the robot's in the repeat's: one anchor
// pair (the taught pose of a place and the repeat's odometry there) maps one into the other.
#pragma once

#include <optional>
#include <vector>

#include "mapless/core/pose.h"

namespace mapless::control {

struct TaughtPathOptions {
  double reached_m = 0.3;          // a taught pose this close counts as reached
  double max_distance_m = 6.0;     // give up after driving this far (odometry) without a match
  double max_omega_radps = 0.6;    // turn-rate limit
  double turn_in_place_rad = 0.8;  // a target farther off the heading: turn in place to it
  void Validate() const;           // throws InputError naming the field
};

class TaughtPathPursuit {
 public:
  // `taught`: the poses to drive through, in order (teach odometry frame); `anchor_taught` and
  // `anchor_odometry`: one place, in the teach's and in the repeat's odometry frame.
  TaughtPathPursuit(std::vector<Pose2> taught, const Pose2& anchor_taught,
                    const Pose2& anchor_odometry, TaughtPathOptions options);
  // The command at odometry pose `now` (forward speed `speed_mps` at most); nullopt once every
  // taught pose is reached or max_distance_m is driven: the stretch is over.
  std::optional<Twist2> Command(const Pose2& now, double speed_mps);
  double driven_m() const { return driven_m_; }
  int target() const { return target_; }  // index into `taught` of the pose driven to
  int size() const { return static_cast<int>(taught_.size()); }

 private:
  std::vector<Pose2> taught_;  // in the repeat's odometry frame
  TaughtPathOptions options_;
  int target_ = 0;
  double driven_m_ = 0.0;
  std::optional<Pose2> last_;
};

}  // namespace mapless::control
