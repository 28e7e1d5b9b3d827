// Appearance-based steering from sub-window correspondences (Section 3 of Payá et al.,
// ../shared/papers/incremental_pca_markov_route_following.md, Fig. 2-4).
//
// Input: correspondences (query window A..E = 0..4, stored window index) between five sub-windows
// of the current image and the N' sub-windows of the matched route image. When the view is aligned
// with the route image, query window q matches stored window c_q = q (N' - 1)/4, so the points
// (q, stored) lie on a line of slope (N' - 1)/4 (the paper's "near N'/5" for its window layout).
// Seven least-squares lines are fitted (windows A-B, A-C, A-D, all, B-E, C-E, D-E), outliers are
// removed from each, and the most confident fit is chosen by the number of correspondences it
// keeps, its residual and a slope near the expected one (optionally the better-sloped half; see
// prefer_undistorted_half). Its ordinate, taken at the image centre
// and relative to the aligned position, is the shift of the view in windows: positive means the
// scene sits further right in the route image than now, so the robot turns left (paper: positive
// ordinate, turn left). The linear speed falls with the size of the correction and the confidence.
#pragma once

#include <string>
#include <vector>

#include "mapless/core/pose.h"

namespace mapless::control {

struct WindowCorrespondence {
  int query = 0;   // 0 = A ... 4 = E
  int stored = 0;  // index of the stored sub-window (0 .. window_count - 1)
};

struct SubWindowSteeringOptions {
  // A correspondence is an outlier when it lies further than this from the line, in windows
  // (and more than outlier_fraction_of_slope times the expected slope).
  double outlier_windows = 2.0;
  double outlier_fraction_of_slope = 0.2;
  // A fit is acceptable when its slope is within this fraction of the expected slope.
  double slope_tolerance = 0.5;
  int min_inliers = 3;  // fewer inliers in every fit: no decision (stop)
  // Read the ordinate from the half (A-C or C-E) whose slope is nearer the expected one when both
  // fit: a side with near objects that loom bends its correspondences (see the .cc). Not in the
  // paper. With the lower gain below it takes the outdoor off-route-right start from 2/10 to
  // 10/10 successes (docs/appearance_route_following.md).
  bool prefer_undistorted_half = true;
  // omega = gain * shift (px of the low-resolution image). 0.02 turned the follower towards a
  // looming parked car faster than the car's view could settle (docs).
  double turn_gain_radps_per_px = 0.012;
  double max_turn_rate_radps = 0.5;
  double max_speed_mps = 0.3;
  double shift_for_stop_px = 12.0;  // the speed falls linearly to zero at this |shift|
  double min_speed_fraction = 0.2;  // ... but not below this fraction while the fit is confident
  void Validate() const;
};

struct SubWindowSteering {
  bool ok = false;
  std::string reason;          // why there is no decision (ok = false)
  std::string fit;             // which windows the chosen fit used, e.g. "A-E", "B-E"
  int inliers = 0;             // correspondences kept by the chosen fit
  int outliers = 0;            // correspondences it removed
  double slope = 0.0;          // fitted slope, windows per query window
  double shift_windows = 0.0;  // ordinate at the centre (window C) minus the aligned index
  double shift_px = 0.0;       // the same in pixels (times the scan step)
  double residual_rms = 0.0;   // of the inliers, windows
  double confidence = 0.0;     // 0..1
  Twist2 twist;                // zero when !ok
};

// The command for a view shifted by `shift_px` (the low-resolution image's pixels): the turn
// rate in proportion, the speed falling with the size of the correction.
Twist2 SteeringTwist(double shift_px, const SubWindowSteeringOptions& options);

// `window_count` = N', `step_px` = the horizontal scan step of the sub-windows.
SubWindowSteering ComputeSubWindowSteering(const std::vector<WindowCorrespondence>& matches,
                                           int window_count, int step_px,
                                           const SubWindowSteeringOptions& options);

}  // namespace mapless::control
