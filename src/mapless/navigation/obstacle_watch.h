// Obstacle watch (not in the papers): the ground ahead, checked every frame while a route is
// repeated or followed, with the dominant plane of the visual-potential paper (Ohnishi & Imiya,
// Sections 3.3-3.5) instead of any map or range sensor.
//
// The current frame is compared with an earlier one taken at least `baseline_m` of commanded
// forward motion before (a 2 cm frame-to-frame step gives sub-pixel parallax at 1.5 m; 8 cm gives
// several pixels). The flow between them is measured on a grid of points in the lower image
// (pyramidal Lucas-Kanade; each frame's pyramid is built once and kept with it); the ground's
// flow is fitted to it as one homography by RANSAC (the dominant plane), with the hypotheses
// drawn from the bottom rows (the ground a robot that is not touching anything stands on: a box
// 1.1 m ahead covers more of the lower image than the ground and moves like a plane too) and their
// support counted on the whole lower image; the points of the region the robot will drive over
// next (the strip of ground as wide as the robot, up to about 2 m ahead) that do not move like
// that plane are obstacle points, unless they lie next to a feature whose descriptor matches the
// route (the taught scene: a wall the route turns in front of is not new) or their backward track
// does not return to within `max_round_trip_px` (a wrong track, dropped from the region's count;
// only the points off the plane are tracked back, which halves the cost of
// the check). When more than `min_blocked_fraction` of the region's points are obstacle points on
// `confirm_frames` successive checks, or more than `single_check_fraction` on one, the watch
// reports an obstacle and stays blocked: the robot stops.
//
// Departure from the paper: sparse flow on a grid instead of dense flow. With DIS (fast or
// medium, at full or half resolution) on the 8 cm pairs the ground's flow was wrong over whole
// blocks of the region (DIS works on patches at a quarter of the resolution): 0.3-0.6 of the
// region flagged on an empty floor. A tracked point with a round-trip check is right or dropped.
//
// A stopped robot sees no parallax, so while blocked the watch compares the region where the
// obstacle was with the same region when the robot had come to a halt; when the grey levels there
// have changed by more than `free_difference` (the obstacle was taken away: the ground behind it
// is in view) on `confirm_frames` successive frames, it lets the robot go on, and the flow check
// starts again once the robot has moved a baseline.
//
// No calibration: the region is given in image fractions. For the simulator's camera (60 degrees
// horizontal field of view, f = 277 px at 320x240, 0.4 m above the ground, level) the default
// rows are the ground from 0.92 m (the bottom row) to 2.1 m ahead of the camera (row 0.72), and
// the strip is +-0.27 m wide (the robot's 0.2 m radius and 7 cm); a robot whose camera sits
// higher, is tilted or sees wider sets them in its YAML file.
#pragma once

#include <array>
#include <deque>
#include <limits>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "mapless/core/pose.h"

namespace mapless::navigation {

struct ObstacleWatchOptions {
  // On by default (issue 21: `--on-obstacle stop` is the default); false: the paper's repeat.
  // False alarms measured on table1 and funnel-scenarios: docs/teach_and_repeat.md#obstacle-watch.
  bool enabled = true;
  // `--on-obstacle avoid` (repeat only): go round the obstacle instead of waiting for it to be
  // taken away (control/detour.h; needs the robot's odometry, without it the robot stops).
  bool avoid = false;
  // The strip's half-width on the ground (the robot's half-width and the margin region_width
  // stands for; 0.27 m for the simulator's robot and camera, see above): with avoid, how far
  // aside to step, from the obstacle's extent in the image (control::LateralExtent).
  double region_half_width_m = 0.27;
  double baseline_m = 0.08;       // commanded forward motion between the two frames compared
  double max_baseline_rad = 0.1;  // ... and at most this much commanded heading change
  double max_age_s = 2.0;         // older frames are not used as the earlier frame
  // The region ahead: the strip of ground the robot drives over, rows from region_top (fraction
  // of the image height from the top; 0.72: about 2 m ahead, see above) to the bottom. A strip of
  // constant width on the ground narrows towards the horizon in the image: region_width is the
  // centred fraction of the columns at the bottom row, and the strip's sides meet at the horizon
  // row (`horizon`, a fraction of the height: 0.5 for a level camera). For the simulator's camera
  // 0.5 at the bottom is +-0.27 m: the robot's 0.2 m radius and 7 cm to spare.
  double region_top = 0.72;
  double region_width = 0.5;
  double horizon = 0.5;
  // The ground's distance at region_top (2.1 m for the simulator's camera, see above). With the
  // horizon row it gives every row's distance (a level pinhole camera: distance ~ 1 / (row -
  // horizon)), so that near the route's end the region stops where the route does (Update's
  // route_left_m): what stood beyond the end at teach time is not in the way (issue 42: a chair
  // 0.5 m past the end stopped the robot for good).
  double region_far_m = 2.1;
  double fit_top = 0.55;  // the ground is fitted on the points below this row fraction ...
  double draw_top = 0.8;  // ... RANSAC drawing its samples below this one (see FitGround)
  // At most this many RANSAC hypotheses; fewer when the best one so far makes more very unlikely
  // (the usual adaptive stop, 99.9% confidence, over the bottom rows' inlier share).
  int ransac_iterations = 200;
  int grid_px = 10;                // spacing of the tracked points, pixels
  int window_px = 9;               // Lucas-Kanade window side
  int levels = 3;                  // pyramid levels above the image
  double max_round_trip_px = 0.5;  // forward-backward tracking error allowed
  // Texture a tracked point needs: the smaller eigenvalue of its window's gradient matrix per
  // pixel (OpenCV's minEigThreshold). On a plain floor the image noise alone tracks "well" both
  // ways; it must not count as flow. min_eigen was set with the suites' image noise (sigma 2 grey
  // levels). A frame with less noise needs less: the threshold is noise_eigen_factor times the
  // eigenvalue that noise of the frame's level gives (the median over windows of pure Gaussian
  // noise of sigma grey levels is 1.87e-4 sigma^2, the largest about twice that: 6.7 times it is
  // min_eigen at sigma 2), between min_eigen_clean and min_eigen. Sigma is estimated on every frame
  // from the lower image (Immerkaer's difference of Laplacians, its median); texture adds to the
  // estimate, so a textured frame keeps min_eigen, as before. On a clean camera weaker floors can
  // be checked: a generated floor of half contrast gave 50 tracked points of 330 with 5e-3, too
  // few to find the ground, and 350 with 1e-3, 90% of the bottom rows on one plane. (Raising the
  // threshold above min_eigen on textured frames lost a corridor's box: 0/10 stops.)
  double min_eigen = 5e-3;
  double min_eigen_clean = 5e-4;
  double noise_eigen_factor = 6.7;
  double ransac_px = 1.0;  // RANSAC inlier threshold of the ground fit, pixels
  // A point is an obstacle point when it is farther than tolerance_px + tolerance_relative *
  // |its flow| from where the ground's homography puts it.
  double tolerance_px = 1.0;
  double tolerance_relative = 0.15;
  int min_region_points = 20;  // fewer tracked points in the region: not observed, unless ...
  // ... at least this many of them are obstacle points: an obstacle that fills the region hides
  // the ground's points, and its own face (near, finely textured) gives few tracked points
  // (table1's box on the standard lane: 11 of 19, 14 of 16 while it came within 1 m).
  int min_obstacle_points = 8;
  // One check with more than this fraction of the region's points off the plane (and at least
  // min_obstacle_points of them) is enough: the standard funnel lane turns left and right on
  // alternate frames and every other comparison comes out weaker (table1's box, seed 16: 10 of
  // 17, 2 of 21, 2 of 22, 15 of 16 points as it came within 1 m; two in a row never agreed).
  double single_check_fraction = 0.5;
  // A point within this distance of a feature that matches the route (the caller's known_px) is
  // part of the taught scene, not an obstacle: a wall the route turns in front of was there at
  // teach time. Only something new stops the robot.
  double known_radius_px = 12.0;
  double min_blocked_fraction = 0.15;  // of the region's points: more than this is an obstacle
  int confirm_frames = 2;              // successive checks that must agree (see above)
  double free_difference = 12.0;       // mean |grey change| where the obstacle was (grey levels)
  // Forward motion allowed without a check that observed the region (since the last one, or the
  // start); beyond it the watch stops the robot as for an obstacle (0: no limit, the repeat's
  // default). A robot that weaves turns too much between frames a baseline apart, and a wall or
  // box coming close leaves too few tracked points in the region (a tiled wall's points fail the
  // round trip): either way nothing is checked, and a follower once crept into a wall so
  // (docs/appearance_route_following.md). While the checks go on, each sees the ground 0.92-2.1 m
  // ahead (the simulator's camera), so 0.5 m between two keeps the ground in front covered.
  double max_unchecked_m = 0.0;
  // When max_unchecked_m is reached, the watch first lets the robot creep straight ahead at
  // creep_speed_mps for at most creep_m (ObstacleCheck::creeping: the caller drives so): straight
  // motion gives the check its baseline, and a check that then observes the region ends the creep
  // (it stops the robot if something is there). Only when the creep did not let it check either
  // does the robot stop, saying so (0: stop at once). The creep goes fast enough to cover a
  // baseline within three quarters of max_age_s (CreepSpeedMps), whatever creep_speed_mps says. The
  // ground 0.92-2.1 m ahead was seen before the creep began, so a creep of 0.3 m after 0.5 m
  // unchecked stays on ground that was in view.
  double creep_m = 0.3;
  double creep_speed_mps = 0.1;
  // The region bends with the robot's path: the curvature driven over the last
  // curvature_window_m (heading change over distance) continued ahead, so that on a curve the
  // strip is the ground the robot will drive over, not the ground straight ahead (a follower at the
  // end of a hairpin stopped for a pillar straight ahead of it, its path turning away). 0: a
  // straight strip.
  double curvature_window_m = 0.3;
  double max_curvature_per_m = 2.5;  // the bend's curvature is clamped to this (1 / 0.4 m)
  // Hidden ground (obstacle_watch_hidden.cc): a box without texture of its own in front of the
  // robot is invisible to the flow check (no tracked points on it, and the ground behind it is
  // hidden), and was driven into on generated worlds. So every frame, turning or not, the strip
  // is split into a left, a middle and a right third, and the share of each third's grid points
  // with the texture a tracked point needs (min_eigen) is compared with what the same third had
  // over the last hidden_window_m of driving (its median, from frames at least hidden_gap_m back
  // and within hidden_max_turn_rad of today's heading). A third that had at least
  // hidden_min_reference of its points textured and now has less than hidden_drop times that, on
  // confirm_frames successive frames, is hidden: the robot stops as for an obstacle, and goes on
  // when the view there changes. A floor too plain to have a reference is not judged (its ground
  // is not checked either: max_unchecked_m). 0 for hidden_drop: off.
  double hidden_drop = 0.3;
  double hidden_min_reference = 0.55;
  double hidden_window_m = 1.2;
  double hidden_gap_m = 0.3;
  double hidden_max_turn_rad = 0.3;
  void Validate() const;
  double CreepSpeedMps() const {
    return creep_speed_mps > baseline_m / (0.75 * max_age_s) ? creep_speed_mps
                                                             : baseline_m / (0.75 * max_age_s);
  }
};

struct ObstacleCheck {
  bool observed = false;     // two frames far enough apart were compared this frame
  bool plane_found = false;  // the ground's homography was fitted (observed frames only)
  // Two frames were compared, with tracked points in the bottom rows, but they fit no ground
  // plane: a wall or a large object fills the view (not observed: the region is not measured).
  bool no_ground = false;
  int region_points = 0;          // tracked points in the region (observed frames only)
  double blocked_fraction = 0.0;  // obstacle points among them
  bool blocked = false;           // the watch holds the robot (an obstacle confirmed, not gone)
  bool cleared = false;           // this frame the obstacle was seen to be gone
  double unchecked_m = 0.0;       // forward motion since the last observed check
  // Creeping straight ahead to check the ground (creep_m): drive at creep_speed_mps, no turning.
  bool creeping = false;
  double curvature_per_m = 0.0;          // the region's bend (positive: to the left)
  double min_eigen = 0.0;                // the texture threshold used on this frame (min_eigen)
  std::string reason;                    // why blocked (empty when free)
  std::vector<cv::Point2f> obstacle_px;  // the obstacle points (debug pictures)
  // With avoid: every point below fit_top off the ground's plane (the region's obstacle points
  // and those beside it: the obstacle's extent, walls), for going round.
  std::vector<cv::Point2f> off_plane_px;
  // The textured share of the strip's left, middle and right thirds this frame, and what they had
  // before (hidden_drop; -1: no reference).
  std::array<double, 3> textured{{0.0, 0.0, 0.0}};
  std::array<double, 3> textured_before{{-1.0, -1.0, -1.0}};
};

class ObstacleWatch {
 public:
  explicit ObstacleWatch(ObstacleWatchOptions options = {});

  // One frame (8-bit grey) at t_ns, after the robot drove `forward_m` and turned `turned_rad`
  // (commanded, since the previous frame). `known_px`: pixels of this view that belong to the
  // taught scene (features matching the route, from the previous frame). `route_left_m`: at most
  // this much ground ahead will be driven over (the rest of the route and a margin; infinite when
  // unknown): the region ends there.
  ObstacleCheck Update(const cv::Mat& grey, Timestamp t_ns, double forward_m, double turned_rad,
                       const std::vector<cv::Point2f>& known_px = {},
                       double route_left_m = std::numeric_limits<double>::infinity());
  bool blocked() const { return blocked_; }
  // Drops a confirmed obstacle and the frames seen so far: the robot is going round it (avoid),
  // and the next check needs a new baseline.
  void Resume();
  const ObstacleWatchOptions& options() const { return options_; }

 private:
  struct Frame {
    std::vector<cv::Mat> pyramid;  // its Lucas-Kanade pyramid, grey levels (built once per frame)
    Timestamp t_ns = 0;
    double forward_m = 0.0;   // odometer of commanded forward motion when it was taken
    double turned_rad = 0.0;  // ... and the commanded heading (the sum of signed turning)
  };
  cv::Rect Region(cv::Size size) const;  // the region's bounding box
  bool InRegion(cv::Point2f p, cv::Size size) const;
  // Where p lies across the strip: -1 at its left edge, 1 at its right (infinite: not on the
  // strip's rows).
  double StripOffset(cv::Point2f p, cv::Size size) const;
  // The ground's homography (current -> earlier pixels), or empty when the points below
  // draw_top do not agree on one.
  cv::Mat FitGround(const std::vector<cv::Point2f>& here, const std::vector<cv::Point2f>& there,
                    const std::vector<int>& draw) const;
  ObstacleCheck Look(const cv::Mat& grey, const std::vector<cv::Mat>& pyramid, Timestamp t_ns,
                     const std::vector<cv::Point2f>& known_px);
  // The newest frame at least a baseline behind (null when the robot turned too much since, or
  // it is too old).
  const Frame* BaselineFrame(const cv::Size& size, Timestamp t_ns) const;
  // The check observed the region: the votes, and the robot blocked when they say so.
  void Vote(const cv::Mat& grey, const cv::Rect& region, int obstacle_points, ObstacleCheck* check);
  ObstacleCheck WatchBlocked(const cv::Mat& grey);
  // The ground ahead not checked for max_unchecked_m (and, with creep_m, not while creeping
  // either): stop as for an obstacle over the region.
  void StopUnchecked(const cv::Mat& grey, ObstacleCheck* check);
  // After Look: the unchecked distance, and the creep or the stop when it is too long.
  void Unchecked(const cv::Mat& grey, double forward_m, ObstacleCheck* check);
  // Every frame: the thirds' texture against their reference, and the stop when one is hidden
  // (hidden_drop; obstacle_watch_hidden.cc).
  void Hidden(const cv::Mat& grey, const std::vector<cv::Mat>& pyramid, ObstacleCheck* check);
  // The curvature driven over the last curvature_window_m (history_), and this frame's texture
  // threshold from its noise (obstacle_watch_region.cc).
  double Curvature() const;
  double MinEigen(const cv::Mat& grey) const;
  // Where a ground point seen at `p` now was seen in a frame taken `forward_m` behind and
  // `turned_rad` of heading ago: the ground model the region's options imply (f h from
  // region_far_m at region_top, f from region_width and region_half_width_m; a level camera on the
  // rotation axis), the prior of each tracked point (obstacle_watch_region.cc).
  cv::Point2f PredictGround(cv::Point2f p, cv::Size size, double forward_m,
                            double turned_rad) const;
  // Stops the robot: `why` for this frame, `waiting` while it stays stopped; it goes on when the
  // view in `mask` (over the region) changes.
  void Hold(const cv::Mat& grey, cv::Mat mask, std::string why, std::string waiting,
            ObstacleCheck* check);

  ObstacleWatchOptions options_;
  std::deque<Frame> history_;
  double forward_m_ = 0.0;
  double turned_rad_ = 0.0;
  double route_left_m_ = std::numeric_limits<double>::infinity();  // this frame's (Update)
  int votes_ = 0;
  bool blocked_ = false;
  cv::Mat blocked_image_;     // the frame when the robot had stopped
  cv::Mat blocked_mask_;      // where the obstacle was in it (the region's size)
  int settle_ = 0;            // frames since the stop (the first few are the reference view)
  int free_votes_ = 0;        // successive frames with the region changed
  double unchecked_m_ = 0.0;  // forward motion since the last observed check
  bool creeping_ = false;     // creeping to check the ground (creep_m)
  double crept_m_ = 0.0;
  double curvature_ = 0.0;   // the region's bend on this frame (Curvature)
  double min_eigen_ = 0.0;   // the texture threshold on this frame (MinEigen)
  std::string blocked_why_;  // what holds the robot (WatchBlocked's reason)
  struct Texture {
    double forward_m = 0.0;
    double turned_rad = 0.0;
    std::array<double, 3> share{};  // textured share of each third (-1: too few points)
  };
  std::deque<Texture> textures_;  // the last frames' (Hidden)
  int hidden_votes_ = 0;
};

}  // namespace mapless::navigation
