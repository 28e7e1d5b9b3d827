// The repeat phase of visual teach & repeat: Algorithm 1 of Kassir et al.
//
// At the start of each segment the current frame's features are detected and matched with the
// segment's destination keyframe; inside the segment the matched features are tracked with KLT and
// the funnel-lane controller (sloped or standard) turns their image coordinates into a command.
// When fewer than `min_features` remain, features are detected and matched again; while that still
// gives too few, the robot stops, and if it cannot recover within `abort_after_s` the repeat aborts
// with a clear status: it never drives blind. The segment switches to the next keyframe by the
// StdRatio/ED criterion (Section VI) or, as an option, Chen & Birchfield's MSE criterion.
//
// Indexing: the robot starts at keyframe 0; segment j runs from keyframe j to its destination,
// keyframe j + 1 (Algorithm 1 writes it KF_{j+1}). Image coordinates are relative to the principal
// point, taken as the image centre: no calibration.
#pragma once

#include <memory>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "mapless/control/detour.h"
#include "mapless/control/funnel_lane.h"
#include "mapless/control/taught_path.h"
#include "mapless/core/worker.h"
#include "mapless/features/features.h"
#include "mapless/features/klt.h"
#include "mapless/navigation/camera_check.h"
#include "mapless/navigation/experiences.h"
#include "mapless/navigation/obstacle_watch.h"
#include "mapless/route/route.h"

namespace mapless::navigation {

enum class Controller { kSloped, kStandard };
// kLocalScale (not in the paper): every keyframe by the local scale, as the route's end is by
// default (see RepeatOptions::end_by_local_scale).
enum class Switching { kStdRatio, kMse, kLocalScale };
Controller ParseController(const std::string& name);  // "sloped", "standard"
Switching ParseSwitching(const std::string& name);    // "stdratio", "mse", "scale"
const char* ControllerName(Controller c);

struct RepeatOptions {
  Controller controller = Controller::kSloped;
  Switching switching = Switching::kStdRatio;
  features::FeatureOptions features;                 // must describe like the route's detector
  features::MatchOptions matching{0.8, 30.0, true};  // ratio, max |dy| px, mutual
  features::KltOptions klt;
  control::SlopedFunnelLaneOptions sloped;
  control::StandardFunnelLaneOptions standard;
  control::SwitchOptions switch_rule;
  int mse_rising_frames = 2;
  int switch_confirm_frames = 3;  // the StdRatio/ED condition must hold this many frames
  // ... and this many for the last keyframe, whose switch ends the route: an early end cannot be
  // caught up by a later segment.
  int final_confirm_frames = 3;
  // The route's end (not in the paper): the last keyframe counts as passed when the local scale
  // (control::MeasureLocalScale) exceeds min_std_ratio and ED < max_ed_px for
  // final_confirm_frames frames, whatever `switching` is. Off the taught path StdRatio crosses 1
  // up to 0.7 m early, and an early end cannot be caught up by a later segment; the local scale
  // compares features on one object with each other, which a lateral offset does not change.
  // With fewer than local_scale.min_pairs nearby pairs the last keyframe is switched like the
  // others. false: always like the others (the paper).
  bool end_by_local_scale = true;
  control::LocalScaleOptions local_scale;
  int min_switch_features = 20;      // no switching on fewer features (their spread is noise)
  double ransac_threshold_px = 3.0;  // outlier rejection of matches by a fundamental matrix
                                     // (RANSAC, needs no calibration); 0 disables it
  int min_features = 10;             // NoF threshold of Algorithm 1
  // Also detect and match afresh every this many frames (0: only when features run short, as in
  // Algorithm 1). KLT tracks drift over long segments and bias StdRatio (the switch then comes
  // up to 1 m early or late); fresh matches do not. Default: every frame.
  int redetect_every_frames = 1;
  double abort_after_s = 10.0;  // stopped this long without enough features: abort
  // Keyframe recovery (not in the paper): while the destination keyframe cannot be matched (its
  // landmarks gone: a parked car that has left), the current frame is also matched with the
  // following keyframes, at most recovery_keyframes ahead: the one after the unmatched keyframe,
  // and farther ones only as far as the robot may have driven: keyframe k - 1 taught at most
  // recovery_time_factor times the time the robot has driven since the last switch after the
  // unmatched keyframe (the funnel lane has no odometry; the time with a moving command is its
  // measure). The nearest one with at least recovery_min_features matches becomes the
  // destination; with none the robot stops and aborts as before. 0 keyframes: off (the paper).
  // Recovery starts once the destination has been short of features for recovery_after_s: a
  // shortage that passes by itself (a few frames of blur) is waited out, not skipped. The
  // shortage begins at a frame with fewer than min_features matches and ends only at one with
  // recovery_min_features (a few matches that come and go do not end it). 3 by default: with
  // it every row of table1 and funnel-scenarios is as without it, indoor_30m standard 9/10
  // instead of 8/10 (docs/teach_and_repeat.md#keyframe-recovery).
  int recovery_keyframes = 3;
  double recovery_after_s = 2.0;
  double recovery_time_factor = 1.5;
  int recovery_min_features = 20;
  // Carrying on (not in the paper): when recovery finds no keyframe and the route has the
  // taught odometry (route::Keyframe::odometry; a teach with odometry) and the frames have the
  // robot's, the robot drives the taught path by odometry (control/taught_path.h) through the
  // unmatched keyframe and up to carry_on_keyframes after it, matching each of them every
  // frame; the first that matches becomes the destination and the funnel lane takes over. It
  // gives up after carry_on.max_distance_m (then waits and aborts as before). The obstacle watch
  // guards the way, and must see it: carrying on is driving without the route's view, most often
  // because something new hides it, so it gives up as soon as the watch has not observed the
  // ground ahead over carry_on_unchecked_m of forward motion (a box without texture in front of
  // the robot hides the keyframe and the ground's points alike, and was driven into so).
  // max_distance_m = 0: off. As with recovery, a keyframe k farther than the next one qualifies
  // only as far as the robot has come: keyframe k - 1 taught at most carry_on_reach_factor times
  // the robot's odometry displacement since the last switch from keyframe destination - 1 (straight
  // lines both). Without it a far keyframe of a straight route, which looks like the near one from
  // afar, could end carrying on metres too early.
  control::TaughtPathOptions carry_on;
  int carry_on_keyframes = 6;
  double carry_on_unchecked_m = 0.3;
  double carry_on_reach_factor = 1.25;
  // Guided matching (not in the paper): matches must lie within this many pixels of the
  // horizontal displacement predicted from the previous frame (at a segment switch: the previous
  // displacement minus the teach-time shift between the two keyframes). A repeating texture then
  // cannot match one period away. 0 disables it. The prediction is dropped after waiting
  // guided_release_s for features, so a wrong prediction cannot hold the robot forever.
  double guided_window_px = 40.0;
  double guided_release_s = 1.0;
  CameraCheckOptions camera;  // camera faults: the robot waits, the session carries on after
  // Obstacle watch (not in the paper; obstacle_watch.h): something on the route ahead stops the
  // robot (status "blocked") until it is gone. On by default; enabled = false: the paper's repeat.
  // With obstacle.avoid the robot goes round it instead (control/detour.h, by odometry: a frame
  // without odometry stops as without avoid), at most max_detours times per destination keyframe
  // (then it stops and waits as without avoid), and re-acquires the destination or, when that
  // no longer matches with recovery_min_features, the nearest following keyframe within
  // carry_on_keyframes that does.
  ObstacleWatchOptions obstacle;
  // Near the end of a complete route taught with odometry, the watch looks no farther than the
  // route goes: the taught path left (from the keyframe before the destination, less the commanded
  // forward motion since the switch) and this margin. What stands beyond the end was there at
  // teach time or is not in the way (issue 42).
  double route_end_margin_m = 0.3;
  control::DetourOptions detour;
  int max_detours = 3;
  // At the last keyframe of an incomplete route: false, the repeat ends there (an interrupted
  // teach read from disk); true, the robot waits for the leader that is still teaching it (fleet:
  // see Extend()).
  bool wait_for_leader = false;
  // Experiences (issue 45; experiences.h): a keyframe with learned views is matched with each at
  // a new destination and the repeat steers by the one that matches best (its features mapped
  // into the taught view by the view's offset). With learn, the frame at which the switching
  // rule says the robot has reached a keyframe becomes a new view of it when its matches with
  // the view in use are at least experiences.sure_inliers (the place is certain) and fewer than
  // experiences.changed_inliers (it looks different today). TakeLearned() hands them over.
  bool learn = false;
  ExperienceOptions experiences{5, 20, 60};
  // 2: on a frame that detects features afresh, the detection runs on a second thread beside
  // the obstacle watch (both only read the frame), so a robot's second core takes the watch's
  // time off the frame's latency. The decisions are the same as with 1 (repeat_detect.cc).
  int threads = 1;
  void Validate() const;
};

// kBlocked: stopped by the obstacle watch, going on by itself when the way is free.
enum class RepeatStatus { kDriving, kWaiting, kCompleted, kAborted, kBlocked };
const char* RepeatStatusName(RepeatStatus s);

// What one frame decided (logged as JSON lines by the apps).
struct RepeatStep {
  RepeatStatus status = RepeatStatus::kDriving;
  std::string reason;        // why the robot is waiting, stopped or aborted
  int destination = 1;       // destination keyframe of the current segment
  int matches = 0;           // matches at the last detection
  int tracked = 0;           // features in use this frame
  bool redetected = false;   // features were detected and matched this frame
  bool switched = false;     // the segment switched this frame
  int recovered_from = -1;   // the switch skipped this keyframe, which could not be matched
  bool carrying_on = false;  // driving the taught path by odometry (RepeatOptions::carry_on)
  bool avoiding = false;     // going round an obstacle (obstacle.avoid; reason: the phase)
  ObstacleCheck obstacle;    // the obstacle watch on this frame
  control::SwitchDecision switching;
  control::LocalScale local_scale;  // measured on the last segment only (end_by_local_scale)
  control::SlopedFunnelLaneResult sloped;
  control::StandardFunnelLaneResult standard;
  int learned = -1;         // this frame was learned as a view of this keyframe (learn)
  std::string learned_why;  // ... and why
  int view = 0;             // the destination's view in use (0: the taught one)
  Twist2 command;           // zero unless driving
  // The features in use after this frame (debug pictures): in the current image and their matches
  // in the destination keyframe, pixels.
  std::vector<cv::Point2f> current_px;
  std::vector<cv::Point2f> destination_px;
};

class RepeatSession {
 public:
  RepeatSession(std::shared_ptr<const route::Route> route, RepeatOptions options);

  // One control period. A camera fault (see camera_check.h) gives kWaiting with the fault as the
  // reason and a zero command; it does not count towards abort_after_s.
  // `odometry`: the robot's odometry pose at the frame, if it has one (only carrying on uses it).
  RepeatStep Update(const cv::Mat& image, Timestamp t_ns,
                    const std::optional<Pose2>& odometry = std::nullopt);
  // A longer snapshot of a route a leader is still teaching (fleet/): the same keyframes and
  // more, or the same ones now complete. At the last keyframe of an incomplete route the robot
  // stops (waiting for the leader) instead of completing, and goes on when the next keyframe
  // arrives; the switching rules are those of a complete route.
  void Extend(std::shared_ptr<const route::Route> route);
  // The views learned so far (RepeatOptions::learn), handed over once; and the view each keyframe
  // was last steered by (-1: never a destination), for ApplyVisit (experiences.h).
  std::vector<LearnedView> TakeLearned() { return std::move(learned_); }
  const std::vector<int>& used_views() const { return chosen_view_; }
  bool finished() const {
    return status_ == RepeatStatus::kCompleted || status_ == RepeatStatus::kAborted;
  }
  int destination() const { return destination_; }

 private:
  RepeatStep Decide(const cv::Mat& image, Timestamp t_ns);
  // The stages of Decide, each true when the frame's decision is made (returned in `step`):
  // A live route: on to the keyframe the leader taught since (false: still waiting, or done).
  bool NextTaughtKeyframe(RepeatStep* step);
  // Algorithm 1, lines 16-18 and 20-27, with reacquiring and keyframe recovery; true when the
  // destination has been short of features for recovery_after_s.
  bool TrackDestination(const cv::Mat& grey, Timestamp t_ns, RepeatStep* step);
  // Carrying on along the taught odometry, or stopping (and aborting) while too few match.
  bool HoldOrCarryOn(Timestamp t_ns, bool short_long, RepeatStep* step);
  // Line 9: the switch to the next segment (and the route's end); `pairs` then for the new one.
  bool SwitchSegment(const cv::Mat& grey, Timestamp t_ns, std::vector<control::FeaturePair>* pairs,
                     RepeatStep* step);
  void DetectAndMatch(const cv::Mat& grey, RepeatStep* step);
  // The current frame's features (extracted once per frame) matched with keyframe k, outliers
  // rejected: current pixels and keyframe pixels.
  // `descriptor_matched` (optional): every current feature whose descriptor matched keyframe k,
  // before the geometric outlier rejection (the taught scene, for the obstacle watch).
  // Matches keyframe k: its chosen view, or every view when none is chosen yet or the chosen one
  // matches too little (the best becomes the chosen one).
  void MatchKeyframe(int k, std::vector<cv::Point2f>* current_px,
                     std::vector<cv::Point2f>* keyframe_px,
                     std::vector<cv::Point2f>* descriptor_matched = nullptr);
  // Keyframe recovery (RepeatOptions::recovery_keyframes): the nearest following keyframe the
  // robot may have reached that the current frame matches, switched to; false when none does.
  bool Recover(RepeatStep* step);
  // Switches to the nearest keyframe in [first, last] that the current frame matches with at
  // least recovery_min_features (and min_features); false when none does. Only keyframes k whose
  // k - 1 the robot may have reached: `reach.taught_s` >= 0, taught at most that long after the
  // keyframe before the destination; `reach.taught_m` >= 0, taught at most that far (odometry,
  // straight line) from it.
  struct Reach {
    double taught_s = -1.0;
    double taught_m = -1.0;
  };
  bool SwitchToMatching(int first, int last, Reach reach, RepeatStep* step);
  // Carrying on (RepeatOptions::carry_on): starts it if it can; the command of this frame, or
  // nullopt when it cannot start or has given up.
  std::optional<Twist2> CarryOn(Timestamp t_ns, RepeatStep* step);
  // Keyframe k becomes the destination with these matches (recovery, carrying on, avoid).
  void SwitchTo(int k, std::vector<cv::Point2f> current_px, std::vector<cv::Point2f> keyframe_px,
                std::vector<cv::Point2f> scene_px, RepeatStep* step);
  // After a detour: the keyframe in [destination, destination + carry_on_keyframes] that the
  // current frame matches best (at least recovery_min_features) becomes the destination.
  void Reacquire(RepeatStep* step);
  void MarkSwitch();  // a new destination: the recovery and carrying-on bookkeeping restart
  // Avoid (RepeatOptions::obstacle.avoid; repeat_avoid.cc): starts a detour round the obstacle
  // the watch has just confirmed; false when it cannot (no odometry, too many detours).
  bool StartDetour(const ObstacleCheck& obstacle, cv::Size image);
  // This frame of the detour under way, the watch's check of the frame.
  RepeatStep Detouring(RepeatStep step, const ObstacleCheck& obstacle);
  double RouteSpeed() const;
  // How much ground ahead the robot may still drive over (RepeatOptions::route_end_margin_m):
  // infinite for an incomplete route or one without odometry.
  double RouteLeftM() const;
  std::vector<control::FeaturePair> Pairs() const;
  RepeatStep Stop(RepeatStep step, RepeatStatus status, const std::string& reason);

  // The obstacle watch on this frame, `dt` after the last; with threads 2, on a second thread
  // while this one detects the frame's features, when the frame will likely need them
  // (repeat_detect.cc). FrameFeatures: this frame's features, detected once.
  ObstacleCheck WatchAndDetect(const cv::Mat& grey, Timestamp t_ns, double dt);
  const features::Features& FrameFeatures(const cv::Mat& grey);

  std::shared_ptr<const route::Route> route_;
  RepeatOptions options_;
  features::FeatureExtractor extractor_;
  std::optional<features::Features> frame_features_;
  std::unique_ptr<Worker> watcher_;  // threads 2: the watch's thread
  CameraMonitor camera_;
  ObstacleWatch watch_;
  Twist2 last_command_;
  std::vector<features::Features> keyframe_features_;
  // Learned views of each keyframe (route::Keyframe::views), and the view chosen for it (0: the
  // taught one, i + 1: learned view i; -1: not chosen yet).
  struct View {
    features::Features features;
    double offset_px = 0.0;
  };
  std::vector<std::vector<View>> learned_views_;
  std::vector<int> chosen_view_;
  std::vector<LearnedView> learned_;
  void AddKeyframeFeatures(const route::Keyframe& kf);
  // The views of keyframe `at` (kf) not in learned_views_[at] yet.
  void AddNewViews(std::size_t at, const route::Keyframe& kf);
  // Matches keyframe k's view v (0: the taught one), keyframe points in the taught view's pixels.
  void MatchView(int k, int v, std::vector<cv::Point2f>* current_px,
                 std::vector<cv::Point2f>* keyframe_px,
                 std::vector<cv::Point2f>* descriptor_matched) const;
  // At a switch: the current frame as a new view of the keyframe reached (RepeatOptions::learn).
  void MaybeLearn(RepeatStep* step);
  // Upper median of b.x - a.x over the pairs (0 when empty); repeat.cc says why not the average
  // of the two middle values.
  static double MedianDx(const std::vector<cv::Point2f>& a, const std::vector<cv::Point2f>& b);
  control::MseSwitch mse_;
  double cx_ = 0.0;
  int destination_ = 1;
  RepeatStatus status_ = RepeatStatus::kDriving;
  cv::Mat previous_;
  std::vector<cv::Point2f> current_px_;      // matched features, tracked in the current images
  std::vector<cv::Point2f> destination_px_;  // their matches in the destination keyframe
  // The taught scene in the last frame, for the obstacle watch: the features whose descriptors
  // matched the destination (also those the epipolar or homography check then rejected: at a
  // turn the homography wins and the near objects' matches, right under parallax, are outliers
  // to it) on a frame detected afresh, the tracked matches otherwise.
  std::vector<cv::Point2f> scene_px_;
  double watch_unchecked_m_ = 0.0;  // this frame's ObstacleCheck::unchecked_m (0: no watch)
  int last_matches_ = 0;
  bool have_expected_dx_ = false;  // guided matching: a predicted x_current - x_destination
  double expected_dx_ = 0.0;
  int switch_votes_ = 0;
  bool waiting_for_route_ = false;  // passed the last keyframe of an incomplete route
  int frames_since_detect_ = 0;
  features::Features current_;  // the features of the last frame detected afresh
  Timestamp last_t_ns_ = 0;
  bool have_last_t_ = false;
  double driven_since_switch_s_ = 0.0;  // time with a moving command since the last switch
  double driven_since_switch_m_ = 0.0;  // commanded forward motion since the last switch
  bool waiting_ = false;
  Timestamp waiting_since_ns_ = 0;
  std::optional<Timestamp> short_since_ns_;  // the destination short of features since
  std::optional<Pose2> odometry_;            // this frame's
  std::optional<Pose2> switch_odometry_;     // at the last switch (the robot at keyframe dest - 1)
  std::optional<control::TaughtPathPursuit> carrying_;
  bool carry_active_ = false;              // driving by carrying_ (paused while matched)
  bool carried_this_destination_ = false;  // gave up on this destination: no second try
  std::optional<control::Detour> detour_;  // going round an obstacle
  int detours_ = 0;                        // detours started for this destination
  int no_ground_frames_ = 0;               // successive frames without the ground ahead
  bool reacquire_ = false;                 // a detour ended: find the route's keyframe again
};

}  // namespace mapless::navigation
