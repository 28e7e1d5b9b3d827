// Going round an obstacle on the route (issue 21, `--on-obstacle avoid`; not in the papers): the
// side from the visual potential (Ohnishi & Imiya, Eq. 8-16) on the obstacle watch's map of the
// ground ahead, the way round by odometry in steps, each step ended by a look ahead.
//
// The repeat stands where the obstacle watch stopped it (the obstacle about 1 m ahead). Its pose
// there and heading define the route's line (x along the heading, y to the left); the detour then
//   0. backs off along the line by back_off_m (the way it came, driven a moment ago): the camera
//      does not see the ground within about 0.9 m, and the looks below must see the obstacle,
//   1. turns in place out to the chosen side (the force's angle theta of Eq. 16, clamped),
//   2. drives straight until it is off the line by the obstacle's extent on that side (measured
//      in the image where the watch stopped it, ObstacleExtent; at least the strip's edge, since
//      the obstacle stands in the strip and its points near an edge are often missed), the
//      strip's half-width and a margin; something in the way of this step (a wall the turn
//      faces) sends it round the other side, once,
//   3. turns back parallel to the line and creeps until the watch has looked at the strip ahead:
//      still blocked (or nothing seen within look_max_m: not known to be free), a step further
//      aside (2-3 again),
//   4. passes: drives parallel to the line at that offset until pass_m beyond where it stopped
//      (the obstacle was at most about 2 m ahead, the camera does not see the ground within
//      about 0.9 m: the obstacle leaves the view before the robot is past it),
//   5. rejoins the line by pure pursuit; done within rejoined_m of it.
// The caller re-acquires the route's keyframe then. A confirmed obstacle while passing or
// rejoining sends the robot a step further aside; stepping aside beyond max_offset_m, or
// something in the way while stepping aside on both sides, fails the detour (the robot stops).
//
// Departure from the paper's law (T = T_m cos theta, R = R_m sin theta every frame, Eq. 17): that
// needs the dominant plane on every frame, and a level camera 0.4 m above the ground sees ground
// only in the lower half of its image, loses the plane while turning in place, and does not see
// the obstacle once it is within 0.9 m. Measured: `mapless navigate` on obstacle_box_table1's
// level camera spent most frames without a ground plane. docs/teach_and_repeat.md#avoid.
#pragma once

#include <opencv2/core.hpp>
#include <vector>

#include "mapless/control/visual_potential.h"
#include "mapless/core/pose.h"

namespace mapless::control {

struct DetourOptions {
  double back_off_m = 0.4;  // reversing along the line before stepping aside
  // Heading off the line while stepping aside: |theta| of the potential's force, clamped to this
  // range. Steep: each step then brings the robot little closer to the obstacle.
  double turn_out_min_rad = 1.2;
  double turn_out_max_rad = 1.4;
  double first_step_m = 0.3;         // the first lateral step off the line at least
  double step_m = 0.2;               // each further step while the way ahead is still blocked
  double margin_m = 0.1;             // beside the obstacle's extent and the strip's half-width
  double max_offset_m = 1.5;         // stepping aside farther than this: the detour fails
  double look_max_m = 0.2;           // creep at most this far for one look ahead
  double look_speed_fraction = 0.5;  // of the speed, while creeping to look
  double pass_m = 3.0;        // drive past until this far along the line from where it stopped
  double lookahead_m = 1.0;   // pure pursuit along the offset lane and back to the line
  double rejoined_m = 0.1;    // this close to the line: done
  double aligned_rad = 0.03;  // turning in place ends within this of the target heading
  double max_omega_radps = 0.6;
  void Validate() const;  // throws InputError naming the field
};

// The watch's view of the strip ahead on one frame.
enum class AheadView {
  kUnknown,  // not observed (no baseline yet, a plain floor)
  kFree,     // observed, below the watch's blocked fraction
  kSuspect,  // observed, above it on this frame (not yet confirmed)
  kBlocked,  // confirmed by the watch
};

enum class DetourPhase {
  kBackOff,
  kTurnOut,
  kStepAside,
  kTurnBack,
  kLook,
  kPass,
  kRejoin,
  kDone,
  kFailed
};
const char* DetourPhaseName(DetourPhase phase);

// The side and angle to step aside by: Eq. 8-16 on the map of the lower image (from row
// top_fraction of `image` down) where `obstacle_px` are obstacle points and the rest is taken as
// ground, with the attraction the desired flow towards theta_d_rad (0: ahead; Eq. 13 with the
// paper's uniform pure flows). Returns theta of Eq. 16 (positive: to the left); a sigma of half
// the image (Eq. 9) makes its side component small, but its sign is the side with more ground.
double DetourAngle(const std::vector<cv::Point2f>& obstacle_px, cv::Size image, double top_fraction,
                   double point_radius_px, double theta_d_rad,
                   const VisualPotentialOptions& options);

// The obstacle's lateral extent (metres, positive to the left of the robot's centre line) from
// image points, without calibration: the watch's strip is half_width_m on either side of the
// centre line on the ground and region_width_fraction of the image width at the bottom row, so
// a point at the bottom row lies (column offset / strip half-width in pixels) * half_width_m
// aside. Every point is measured so: an obstacle that stopped the robot stands about as near as
// the nearest ground in view (the camera sees the ground from about 0.9 m; the lowest rows of
// a face that near move almost like the ground and its foot is not found), and a farther
// obstacle comes out narrower than it is (the detour's look ahead then steps further). The
// off-plane points in the region's rows (from region_top_fraction down; a wall farther off is
// above them) fall into clusters wherever neighbours are more than gap_m apart; the clusters
// holding region points are the obstacle.
struct ObstacleExtent {
  bool found = false;
  double left_m = 0.0;   // the obstacle's leftmost lateral position
  double right_m = 0.0;  // its rightmost (smallest)
};
ObstacleExtent MeasureObstacleExtent(const std::vector<cv::Point2f>& region_px,
                                     const std::vector<cv::Point2f>& off_plane_px, cv::Size image,
                                     double region_width_fraction, double region_top_fraction,
                                     double half_width_m, double gap_m = 0.15);

class Detour {
 public:
  // `stopped_at`: the odometry pose where the watch stopped the robot; `theta_rad`: DetourAngle's
  // (its sign is the side); `extent` and `half_width_m`: how far aside to step first, the
  // obstacle's side (at least half_width_m) plus half_width_m and margin_m (beyond max_offset_m:
  // failed at once).
  Detour(const Pose2& stopped_at, double theta_rad, const ObstacleExtent& extent,
         double half_width_m, DetourOptions options);
  // The command at odometry pose `now`, the watch's view of this frame; `speed_mps`: the route's.
  Twist2 Command(const Pose2& now, AheadView ahead, double speed_mps);
  DetourPhase phase() const { return phase_; }
  double side() const { return side_; }          // +1: round by the left, -1: by the right
  double offset_m() const { return offset_m_; }  // the lane's distance off the line
  bool finished() const { return phase_ == DetourPhase::kDone || phase_ == DetourPhase::kFailed; }

 private:
  Twist2 TurnTo(double heading_rad, double now_rad) const;  // in the line's frame
  Twist2 Pursue(const Pose2& local, double x_m, double y_m, double speed_mps) const;
  void StepFurther(double step_m);
  // The first step's offset on `side`: the obstacle's extent there (at least the strip's edge),
  // the strip's half-width and the margin.
  double FirstOffset(const ObstacleExtent& extent, double half_width_m, double side) const;

  Pose2 origin_;  // the line: x along the heading where the robot stopped, y to the left
  DetourOptions options_;
  double side_ = 1.0;
  double turn_out_rad_ = 0.8;
  double offset_m_ = 0.0;             // lateral target of the current step, towards side_
  double other_side_offset_m_ = 0.0;  // the first step's on the other side
  bool tried_other_side_ = false;
  bool look_after_step_ = true;
  Pose2 look_start_;
  DetourPhase phase_ = DetourPhase::kBackOff;
};

}  // namespace mapless::control
