// Appearance-based route following (Payá et al., ../shared/papers/
// incremental_pca_markov_route_following.md): a leader teaches the route by adding low-resolution
// images to an eigenspace one at a time (incremental PCA, Section 2) and publishes each new model;
// a follower localizes itself on the route (initial localization by clustering, Section 4; then
// Markov localization, Section 4, or the nearest projection, Section 3) and steers from the
// sub-window correspondences with the route image ahead (Section 3), while the leader may still be
// teaching. No threads, files or clocks here: the caller feeds frames and odometry.
//
// Safety: the follower stops and says why when it has no consistent sub-window fit, when the
// localization is lost (it then re-localizes with the same small motions as at the start), and
// when it reaches the end of a route that is still being taught (it waits for the leader).
#pragma once

#include <deque>
#include <memory>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "mapless/appearance/image.h"
#include "mapless/appearance/pca.h"
#include "mapless/appearance/subwindow.h"
#include "mapless/control/subwindow_steering.h"
#include "mapless/control/taught_path.h"
#include "mapless/core/pose.h"
#include "mapless/localization/initial.h"
#include "mapless/localization/markov.h"
#include "mapless/navigation/appearance_experiences.h"
#include "mapless/navigation/camera_check.h"
#include "mapless/navigation/obstacle_watch.h"
#include "mapless/route/appearance_route.h"

namespace mapless::navigation {

struct AppearanceLeaderOptions {
  double image_spacing_m = 0.2;  // a route image every this much odometry distance ...
  double image_turn_rad = 0.2;   // ... or heading change (turns in place), and the first frame
  bool incremental = true;  // false: batch PCA once the route is finished (the classical method:
                            // nothing can follow before)
  appearance::AppearanceImageOptions image;
  appearance::SubWindowOptions windows;
  appearance::IncrementalPcaOptions pca;  // batch PCA keeps pca.max_dimensions components
  void Validate() const;
};

class AppearanceLeader {
 public:
  explicit AppearanceLeader(AppearanceLeaderOptions options = {});
  // Offers a camera frame and the odometry; returns true when it became a route image.
  bool Update(const cv::Mat& image, const Pose2& odometry);
  // The 8-bit low-resolution image of the last route image Update() stored (for the route store).
  const cv::Mat& last_low() const { return last_low_; }
  double distance_m() const { return distance_m_; }
  // Adds a route image read back from the route store (route/appearance_store.h): the model then
  // equals the leader's that stored it.
  void AddStored(const cv::Mat& low, double distance_m, const Pose2& odometry);
  // Adds a learned view of route image `place` (route/appearance_store.h: a version-2 route),
  // after every route image: its projection is column images() + views so far.
  void AddStoredView(int place, const cv::Mat& low, double offset_px);
  // The route is complete (batch PCA is computed here when incremental is false).
  void Finish();
  // The current route as an immutable snapshot (null before any image, or before Finish() for
  // batch PCA). O(M K L) for the incremental model.
  std::shared_ptr<const route::AppearanceRoute> Snapshot() const;
  int images() const { return static_cast<int>(images_.size()); }

 private:
  void Add(const cv::Mat& low8, double distance_m, const Pose2& odometry);

  AppearanceLeaderOptions options_;
  cv::Mat last_low_;
  appearance::IncrementalPca pca_;
  std::vector<appearance::Vector> vectors_;  // batch mode only
  std::vector<std::shared_ptr<const route::AppearanceRouteImage>> images_;
  std::vector<std::shared_ptr<const route::AppearanceRouteView>> views_;
  std::vector<std::vector<int>> place_views_;
  appearance::Eigenspace batch_;
  bool finished_ = false;
  double distance_m_ = 0.0;
  bool have_last_ = false;
  Pose2 last_odometry_;
  Pose2 last_stored_;
  double last_stored_distance_m_ = 0.0;
};

struct AppearanceFollowerOptions {
  AppearanceFollowerOptions();  // sets markov.uniform_mixing = 0.01 (used only with
                                // uniform_mixing_for_m > 0) and obstacle.baseline_m = 0.12
  bool use_markov = true;       // false: nearest projection every frame (Section 3 alone)
  appearance::AppearanceImageOptions image;
  appearance::SubWindowOptions windows;
  control::SubWindowSteeringOptions steering;
  localization::MarkovOptions markov;
  localization::ClusteringOptions clustering;
  // Initial localization: turn in place to +init_turn_rad, to -init_turn_rad and back to the start
  // heading, then creep forward init_forward_m, localizing every frame.
  double init_turn_rad = 0.25;
  double init_turn_rate_radps = 0.5;
  double init_forward_m = 0.15;
  double init_forward_speed_mps = 0.1;
  double init_sigma_images = 2.0;  // belief width around the chosen cluster
  // Where the follower starts: within this distance of the route start (the usual case: it sets
  // off where the leader did), so the initial localization only considers those route images;
  // on a route whose places repeat (identical doors) it cannot otherwise tell the start from its
  // twins. 0: the whole route (the paper's clustering alone).
  double start_window_m = 1.0;
  // Arrival: at the end of a complete route, with at least this probability (Markov), after at
  // least min_follow_frames frames of following (an initial localization at the end is not an
  // arrival).
  double arrive_min_probability = 0.5;
  int min_follow_frames = 10;
  // An image whose grey levels vary less than this (standard deviation) is unusable: the robot
  // stops (black, over-exposed, a featureless wall).
  double min_contrast = 3.0;
  // Stopped this many frames in a row without a steering decision: localize again around the
  // current position (the same small motions as at the start).
  int relocalize_after_stopped_frames = 10;
  // The Markov belief mixes in markov.uniform_mixing only during the first this many metres after
  // each (initial) localization, so that a belief on an aliased twin can give way. Off (0) by
  // default since the ahead limit below: the mixing also let the belief jump back onto the twin
  // 3 m behind (appearance.cc).
  double uniform_mixing_for_m = 0.0;
  // Markov localization is updated once per this much travel, in route images (see Update()).
  double markov_update_images = 0.5;
  // Limits of the Markov belief (not in the paper). A follower that sets off near the route start
  // (start_window_m > 0) cannot get further along the route than it has driven, nor much less far:
  // after the start localization at image i0, with d the distance driven since then by the
  // odometry, the belief is kept within
  //   i0 + (d (1 - behind_fraction) - ahead_margin_m - start_window_m) / spacing  and
  //   i0 + (d (1 + ahead_fraction) + ahead_margin_m) / spacing.
  // Without the upper limit the view from behind the route start, which looks like the view a few
  // metres in, pulls the belief ahead onto an aliased twin; without the lower one, a belief that
  // is momentarily unsure can fall back onto a look-alike place far behind (appearance.cc,
  // docs/appearance_route_following.md). Negative ahead_margin_m: no limits; behind_fraction >= 1:
  // no lower limit.
  double ahead_margin_m = 0.3;
  double ahead_fraction = 0.05;  // the odometry may under-report the distance by this fraction
  double behind_fraction = 0.1;  // ... and the path be this much longer than the route (detours)
  // Near the end of a complete route the lower limit also follows the belief (not in the paper):
  // once the belief has been at route image j, within anchor_end_m of the end, with at least
  // anchor_probability, it is kept from falling further behind j than the distance driven since
  // then allows (the formula above, from j and without start_window_m). Near a wall or a box the
  // low-resolution view changes so fast with a lateral offset that the images ahead stop
  // matching; the belief then stayed on the last image that did while the robot drove on past the
  // route's end (lifelong_indoor, docs/appearance_route_following.md). Past the end the limit
  // reaches the last image and the follower arrives. Only near the end, and only after the robot
  // has driven start_window_m + ahead_margin_m: a follower that starts off the route is
  // confidently ahead of where it is until it has joined the route (Fig. 9 of the paper), and an
  // anchor there kept the belief ahead for good (outdoor_70m off-route-right, 1 of 10 runs).
  // 0: off.
  double anchor_end_m = 2.0;
  double anchor_probability = 0.8;
  int lookahead_images = 1;      // steer towards the route image this far ahead of the position
  int arrive_within_images = 1;  // arrived at the end of a complete route within this many
  // ... and, while the belief limits above are kept, once the odometry has driven the route's
  // length from the start localization's image less this much (not in the paper). Near the end
  // the low-resolution views of the last metre look alike (a wall or the open ground the route
  // ends facing, growing), and the belief ran up to the ahead limit, whose slack grows with the
  // distance (ahead_fraction): followers on generated worlds arrived 0.6-1.1 m early. The
  // odometry's under-report (a real robot's) makes it drive on past the end by that much less
  // this slack; a wall there stops it and it arrives (arrive_blocked_within_images). Negative: off.
  double arrive_odometry_slack_m = 0.3;
  int wait_within_images = 2;  // wait for a leader this close to the end it has taught so far
  // Arrived also when the obstacle watch stops the follower this close to the end of a complete
  // route (not in the paper): what stops it is beyond the end (the wall the route ends facing), as
  // the repeat's watch, cut at the route's end, would not see. Near a wall the belief lags one or
  // two images (the images ahead stop matching with a lateral offset), so it could not reach
  // arrive_within_images there and the follower waited before the wall until its time ran out.
  // Negative: off.
  int arrive_blocked_within_images = 2;
  // Recovery (issue 21; not in the paper), for route images whose view has changed (something
  // that filled them is gone). When the route image ahead and its neighbours give no consistent
  // sub-window fit, the follower tries the route images up to recover_images beyond them, the
  // most probable first by the Markov belief (the belief at the place each would be the one ahead
  // from), and steers towards the first that fits. When none does, it carries on along the
  // leader's odometry (the route images' poses, control/taught_path.h) from its place on the
  // route: the belief then moves with the odometry alone (MarkovLocalizer::Predict: the images
  // are known not to fit, so they are no evidence), and the images ahead are tried every frame;
  // the first fit ends it. After carry_on.max_distance_m without a fit it stops and localizes
  // again around where it is (as without recovery). Both need the Markov belief (use_markov).
  // recover_images = 0, carry_on.max_distance_m = 0: off. The leader's poses are turned by the
  // mean heading difference between the follower and the route images it was at over its last
  // carry_on_heading_frames frames of following (the follower weaves about the route's heading;
  // one frame's heading, often turning as the fits go wrong, drifts aside).
  int recover_images = 10;
  int carry_on_heading_frames = 60;
  control::TaughtPathOptions carry_on;
  // Turns in place (not in the paper): where the leader turned by turn_in_place_min_rad or more
  // while driving less than turn_in_place_max_m, its route images (one every
  // AppearanceLeaderOptions::image_turn_rad) are views from one spot, which the sub-window
  // steering cannot follow (it steers a few degrees at a time while driving on, past the corner:
  // generated worlds with a turn in place, 6 of 19 failures with the watch off). Once localized
  // at such a place, the follower turns in place by odometry to the leader's heading after the
  // turn (the leader's turn, corrected by the follower's mean heading offset over the last frames
  // of following), within turn_in_place_tolerance_rad, then follows the images again.
  double turn_in_place_min_rad = 0.5;
  double turn_in_place_max_m = 0.1;
  double turn_in_place_tolerance_rad = 0.05;
  double turn_in_place_rate_radps = 0.5;
  // Feed-forward (not in the paper): the leader's own turning between the follower's place and
  // the image it steers towards, as a curvature (heading change over odometry distance), times
  // the commanded speed and this factor, is added to the sub-window steering's turn rate. The
  // images alone turned too late on curves: on a generated car park's 90 degree turn of 1.3 m
  // radius the follower's heading lagged the leader's until it left the route. 0: the paper's.
  double leader_turn_feedforward = 1.0;
  CameraCheckOptions camera;  // camera faults: stop until the images are usable again
  // Experiences (issue 45; appearance_experiences.h): learn views of the places whose appearance
  // has changed (learned(), used_views(): the caller writes them into the route). Off by default
  // (`mapless follow --learn`); a route's learned views are used whenever it has them.
  bool learn = false;
  AppearanceExperienceOptions experiences;
  // Obstacle watch (not in the paper; obstacle_watch.h), as in the repeat: something on the way
  // ahead stops the follower (kStopped, the reason says so) until it is gone. On by default;
  // enabled = false: the paper's follower. The route has no features, so everything off the
  // ground in the region counts; the region is the robot-wide strip of ground ahead.
  ObstacleWatchOptions obstacle;
  void Validate() const;
};

enum class FollowerState { kInitializing, kFollowing, kStopped, kWaitingForLeader, kArrived };
const char* FollowerStateName(FollowerState state);

struct FollowerStep {
  FollowerState state = FollowerState::kInitializing;
  Twist2 command;
  int index = -1;            // localization on the route (route image)
  double probability = 0.0;  // Markov: belief mass around it
  int target = -1;           // route image steered towards
  int target_view = -1;      // ... by its taught image (0) or its learned view i - 1 (i >= 1)
  std::string learned;       // why this frame was learned as a view of `index` (learn on)
  bool carrying_on = false;  // driving the leader's odometry (AppearanceFollowerOptions::carry_on)
  std::string reason;        // why the robot is stopped (kStopped, kWaitingForLeader)
  control::SubWindowSteering steering;
  std::vector<float> belief;  // Markov: the belief over the route images after this frame
  ObstacleCheck obstacle;     // the obstacle watch on this frame (blocked: stopped for it)
};

class AppearanceFollower {
 public:
  explicit AppearanceFollower(AppearanceFollowerOptions options = {});
  // One control period: the current image, the odometry and the latest route snapshot. A camera
  // fault stops the robot (kStopped, or kInitializing while it localizes) with the fault as the
  // reason; the frame is otherwise ignored, so localization resumes where it was.
  // t_ns: the frame's time (the obstacle watch compares frames at most max_age_s apart).
  FollowerStep Update(const cv::Mat& image, const Pose2& odometry,
                      const route::AppearanceRoute& route, Timestamp t_ns);
  // Learning (AppearanceFollowerOptions::learn): the views learned so far, and the view each place
  // was last steered by (0 the taught image, i + 1 learned view i, -1 none): what
  // ApplyAppearanceVisit writes into the route.
  const std::vector<LearnedAppearanceView>& learned() const { return learned_; }
  const std::vector<int>& used_views() const { return used_views_; }

 private:
  FollowerStep Decide(const cv::Mat& image, const Pose2& odometry,
                      const route::AppearanceRoute& route);
  bool Localize(const appearance::Vector& projection, double advance_m, const Pose2& odometry,
                const route::AppearanceRoute& route, FollowerStep* step);
  FollowerStep Initialize(const appearance::Vector& projection, const Pose2& odometry,
                          const route::AppearanceRoute& route);
  // centre_index < 0: around the route start (or the whole route when start_window_m is 0).
  void StartInitialization(const Pose2& odometry, int centre_index);
  // Sub-window steering towards the first of `targets` that fits (step->target, step->steering):
  // each by its route image, then, where none fits, by its learned view nearest projection_.
  bool SteerTowards(const std::vector<int>& targets, const cv::Mat& low,
                    const route::AppearanceRoute& route, FollowerStep* step) const;
  // Localization over the route's places: the nearest place in [from, to] (initial
  // localization), and the k nearest (nearest-projection mode).
  int NearestPlaceIn(const route::AppearanceRoute& route, int from, int to) const;
  // Learning (appearance_learn.cc): the place's column nearest projection_, and the view learned
  // of step->index this frame, if it should be.
  int NearestColumnOf(const route::AppearanceRoute& route, int place) const;
  void MaybeLearn(const cv::Mat& image, const cv::Mat& low, const route::AppearanceRoute& route,
                  bool recovered, FollowerStep* step);
  // The obstacle watch stopped the follower within arrive_blocked_within_images of the end of a
  // complete route (by the last localization).
  bool BlockedAtTheEnd(const route::AppearanceRoute& route) const;
  // Recovery: the route images beyond the lookahead target and its neighbours, by belief.
  bool Recover(int ahead, const cv::Mat& low, const route::AppearanceRoute& route,
               FollowerStep* step) const;
  // Carrying on along the leader's odometry from route image step->index: the command, or
  // nullopt when it is off, not possible or given up (then not again before the next fit or
  // localization).
  std::optional<Twist2> CarryOn(const Pose2& odometry, const route::AppearanceRoute& route,
                                FollowerStep* step);

  AppearanceFollowerOptions options_;
  CameraMonitor camera_;
  ObstacleWatch watch_;
  bool have_watch_odometry_ = false;
  Pose2 watch_odometry_;  // the odometry at the previous frame the watch saw
  Twist2 last_command_;
  localization::MarkovLocalizer markov_;
  bool initializing_ = true;
  int init_centre_ = -1;
  int stopped_frames_ = 0;
  bool init_started_ = false;
  int init_phase_ = 0;
  Pose2 init_start_;
  std::vector<int> init_localizations_;
  bool have_odometry_ = false;
  Pose2 last_odometry_;
  bool arrived_ = false;
  int follow_frames_ = 0;
  bool have_localization_ = false;
  localization::Localization last_localization_;
  double pending_advance_images_ = 0.0;
  int last_route_size_ = 0;
  double since_localized_m_ = 0.0;
  double driven_m_ = 0.0;
  int start_index_ = -1;
  int anchor_index_ = -1;         // the furthest confident belief (anchor_probability) ...
  double anchor_driven_m_ = 0.0;  // ... and driven_m_ when it was reached
  std::optional<control::TaughtPathPursuit> carrying_;
  bool carry_given_up_ = false;  // until the next fit or localization
  // A turn in place taught at the route images up to `through` (appearance_turn.cc): turning to
  // target_theta_rad (follower odometry) while active; the images up to `through` are done.
  struct TaughtTurn {
    bool active = false;
    int through = -1;
    double target_theta_rad = 0.0;     // unwrapped: a turn may be more than half a circle
    double unwrapped_theta_rad = 0.0;  // the follower's heading, unwrapped since the turn began
    double last_theta_rad = 0.0;
  };
  TaughtTurn turn_;
  // The command of a taught turn in place at the follower's place (step->index), or nullopt.
  std::optional<Twist2> TurnInPlace(const Pose2& odometry, const route::AppearanceRoute& route,
                                    FollowerStep* step);
  // The leader's curvature from route image `from` to `to` (0 over less than 5 cm).
  static double LeaderCurvature(const route::AppearanceRoute& route, int from, int to);
  // Heading of the follower minus the leader's at its route image, over the last frames of
  // following (carry_on_heading_frames).
  std::deque<double> heading_offsets_;
  // Their circular mean; without any, the current heading minus the leader's at `leader`.
  double HeadingOffset(const Pose2& odometry, const Pose2& leader) const;
  appearance::Vector projection_;  // the current frame's (Decide)
  std::vector<LearnedAppearanceView> learned_;
  mutable std::vector<int> used_views_;  // per place (SteerTowards marks them)
  int last_learn_place_ = -1;            // places up to it have been looked at for learning
};

}  // namespace mapless::navigation
