#include "mapless/navigation/repeat.h"

#include <algorithm>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "mapless/core/check.h"

namespace mapless::navigation {

// Upper median of b.x - a.x over pairs (0 when empty). Not control::Median, which averages the two
// middle values of an even count: the loop scenario's measured 5/10 was made with this one and
// is on the edge (2/10 with the averaged median).
double RepeatSession::MedianDx(const std::vector<cv::Point2f>& a,
                               const std::vector<cv::Point2f>& b) {
  std::vector<double> d;
  d.reserve(a.size());
  for (std::size_t i = 0; i < a.size() && i < b.size(); ++i) d.push_back(b[i].x - a[i].x);
  if (d.empty()) return 0.0;
  const auto mid = d.begin() + static_cast<std::ptrdiff_t>(d.size() / 2);
  std::nth_element(d.begin(), mid, d.end());
  return *mid;
}

Controller ParseController(const std::string& name) {
  if (name == "sloped") return Controller::kSloped;
  if (name == "standard") return Controller::kStandard;
  throw InputError("unknown controller '" + name + "' (known: sloped, standard)");
}

Switching ParseSwitching(const std::string& name) {
  if (name == "stdratio") return Switching::kStdRatio;
  if (name == "mse") return Switching::kMse;
  if (name == "scale") return Switching::kLocalScale;
  throw InputError("unknown switching rule '" + name + "' (known: stdratio, mse, scale)");
}

const char* ControllerName(Controller c) {
  return c == Controller::kSloped ? "sloped" : "standard";
}

const char* RepeatStatusName(RepeatStatus s) {
  switch (s) {
    case RepeatStatus::kDriving:
      return "driving";
    case RepeatStatus::kWaiting:
      return "waiting";
    case RepeatStatus::kCompleted:
      return "completed";
    case RepeatStatus::kAborted:
      return "aborted";
    case RepeatStatus::kBlocked:
      return "blocked";
  }
  return "?";
}

void RepeatOptions::Validate() const {
  experiences.Validate();
  MAPLESS_CHECK(threads == 1 || threads == 2,
                "RepeatOptions.threads = " << threads << "; must be 1 or 2");
  MAPLESS_CHECK(route_end_margin_m >= 0.0,
                "RepeatOptions.route_end_margin_m = " << route_end_margin_m << "; must be >= 0");
  features.Validate();
  matching.Validate();
  klt.Validate();
  camera.Validate();
  obstacle.Validate();
  sloped.Validate();
  standard.Validate();
  switch_rule.Validate();
  local_scale.Validate();
  MAPLESS_CHECK(min_features >= 2,
                "RepeatOptions.min_features = " << min_features << "; must be >= 2");
  MAPLESS_CHECK(redetect_every_frames >= 0, "RepeatOptions.redetect_every_frames = "
                                                << redetect_every_frames << "; must be >= 0");
  MAPLESS_CHECK(abort_after_s > 0.0,
                "RepeatOptions.abort_after_s = " << abort_after_s << "; must be > 0");
  MAPLESS_CHECK(switch_confirm_frames >= 1, "RepeatOptions.switch_confirm_frames = "
                                                << switch_confirm_frames << "; must be >= 1");
  MAPLESS_CHECK(final_confirm_frames >= 1, "RepeatOptions.final_confirm_frames = "
                                               << final_confirm_frames << "; must be >= 1");
  MAPLESS_CHECK(min_switch_features >= 2,
                "RepeatOptions.min_switch_features = " << min_switch_features << "; must be >= 2");
  MAPLESS_CHECK(ransac_threshold_px >= 0.0,
                "RepeatOptions.ransac_threshold_px = " << ransac_threshold_px << "; must be >= 0");
  MAPLESS_CHECK(guided_window_px >= 0.0,
                "RepeatOptions.guided_window_px = " << guided_window_px << "; must be >= 0");
  MAPLESS_CHECK(guided_release_s > 0.0,
                "RepeatOptions.guided_release_s = " << guided_release_s << "; must be > 0");
  MAPLESS_CHECK(recovery_keyframes >= 0,
                "RepeatOptions.recovery_keyframes = " << recovery_keyframes << "; must be >= 0");
  MAPLESS_CHECK(recovery_time_factor > 0.0,
                "RepeatOptions.recovery_time_factor = " << recovery_time_factor << "; must be > 0");
  carry_on.Validate();
  MAPLESS_CHECK(carry_on_reach_factor > 0.0, "RepeatOptions.carry_on_reach_factor = "
                                                 << carry_on_reach_factor << "; must be > 0");
  MAPLESS_CHECK(carry_on_keyframes >= 0,
                "RepeatOptions.carry_on_keyframes = " << carry_on_keyframes << "; must be >= 0");
  MAPLESS_CHECK(carry_on_unchecked_m > 0.0,
                "RepeatOptions.carry_on_unchecked_m = " << carry_on_unchecked_m << "; must be > 0");
  MAPLESS_CHECK(recovery_min_features >= 2, "RepeatOptions.recovery_min_features = "
                                                << recovery_min_features << "; must be >= 2");
  // recovery_after_s >= abort_after_s is allowed: the repeat then aborts before it recovers.
  MAPLESS_CHECK(recovery_after_s >= 0.0,
                "RepeatOptions.recovery_after_s = " << recovery_after_s << "; must be >= 0");
  detour.Validate();
  MAPLESS_CHECK(max_detours >= 0,
                "RepeatOptions.max_detours = " << max_detours << "; must be >= 0");
  MAPLESS_CHECK(mse_rising_frames >= 1,
                "RepeatOptions.mse_rising_frames = " << mse_rising_frames << "; must be >= 1");
}

RepeatSession::RepeatSession(std::shared_ptr<const route::Route> route, RepeatOptions options)
    : route_(std::move(route)),
      options_(options),
      extractor_((options.Validate(), options.features)),
      camera_(options.camera),
      watch_(options.obstacle),
      mse_(options.mse_rising_frames) {
  MAPLESS_CHECK(route_ != nullptr, "RepeatSession: no route");
  MAPLESS_CHECK(route_->keyframes.size() >= 2, "RepeatSession: the route has "
                                                   << route_->keyframes.size()
                                                   << " keyframe(s); at least 2 are needed");
  MAPLESS_CHECK(route_->detector == features::DetectorTypeName(options_.features.type),
                "RepeatSession: the route was taught with '"
                    << route_->detector << "' features but the repeat uses '"
                    << features::DetectorTypeName(options_.features.type) << "'");
  for (const auto& kf : route_->keyframes) AddKeyframeFeatures(kf);
  cx_ = 0.5 * (route_->image_width - 1);
}

void RepeatSession::Extend(std::shared_ptr<const route::Route> route) {
  MAPLESS_CHECK(route != nullptr && route->keyframes.size() >= route_->keyframes.size() &&
                    route->detector == route_->detector &&
                    route->image_width == route_->image_width &&
                    route->image_height == route_->image_height,
                "RepeatSession::Extend: not a continuation of the route");
  for (std::size_t i = 0; i < keyframe_features_.size(); ++i)
    AddNewViews(i, route->keyframes[i]);  // views shared since (a fleet's copy)
  for (std::size_t i = keyframe_features_.size(); i < route->keyframes.size(); ++i)
    AddKeyframeFeatures(route->keyframes[i]);
  route_ = std::move(route);
}

std::vector<control::FeaturePair> RepeatSession::Pairs() const {
  std::vector<control::FeaturePair> pairs;
  pairs.reserve(current_px_.size());
  for (std::size_t i = 0; i < current_px_.size(); ++i) {
    pairs.push_back({current_px_[i].x - cx_, destination_px_[i].x - cx_});
  }
  return pairs;
}

void RepeatSession::MatchView(int k, int v, std::vector<cv::Point2f>* current_px,
                              std::vector<cv::Point2f>* keyframe_px,
                              std::vector<cv::Point2f>* descriptor_matched) const {
  const auto index = static_cast<std::size_t>(k);
  const View* view = v > 0 ? &learned_views_[index][static_cast<std::size_t>(v - 1)] : nullptr;
  const auto& kf = view != nullptr ? view->features : keyframe_features_[index];
  const float offset = view != nullptr ? static_cast<float>(view->offset_px) : 0.0f;
  features::MatchOptions matching = options_.matching;
  if (options_.guided_window_px > 0.0 && have_expected_dx_ && k == destination_) {
    matching.expected_dx_px = expected_dx_ - offset;  // x_current - x in this view
    matching.max_ddx_px = options_.guided_window_px;
  }
  const std::vector<cv::DMatch> matches = features::MatchFeatures(current_, kf, matching);
  current_px->clear();
  keyframe_px->clear();
  for (const auto& m : matches) {
    current_px->push_back(current_.keypoints[static_cast<std::size_t>(m.queryIdx)].pt);
    cv::Point2f p = kf.keypoints[static_cast<std::size_t>(m.trainIdx)].pt;
    p.x -= offset;  // into the taught view's pixels
    keyframe_px->push_back(p);
  }
  if (descriptor_matched != nullptr) *descriptor_matched = *current_px;
  // Outlier rejection: matches must agree with one epipolar geometry, or, for a rotation in place
  // or a distant scene (where the epipolar geometry degenerates), with one homography. Whichever
  // model explains more matches wins. Neither needs calibration.
  if (options_.ransac_threshold_px > 0.0 && current_px->size() >= 12) {
    std::vector<uchar> inlier_f;
    std::vector<uchar> inlier_h;
    const cv::Mat f = cv::findFundamentalMat(*current_px, *keyframe_px, cv::FM_RANSAC,
                                             options_.ransac_threshold_px, 0.99, inlier_f);
    const cv::Mat hom = cv::findHomography(*current_px, *keyframe_px, cv::RANSAC,
                                           options_.ransac_threshold_px, inlier_h);
    const auto count = [](const std::vector<uchar>& m) {
      return std::count(m.begin(), m.end(), 1);
    };
    const long nf = f.empty() || inlier_f.size() != current_px->size() ? 0 : count(inlier_f);
    const long nh = hom.empty() || inlier_h.size() != current_px->size() ? 0 : count(inlier_h);
    if (nf > 0 || nh > 0) {
      const std::vector<uchar>& inlier = nf >= nh ? inlier_f : inlier_h;
      std::vector<cv::Point2f> cur, dst;
      for (std::size_t i = 0; i < inlier.size(); ++i) {
        if (!inlier[i]) continue;
        cur.push_back((*current_px)[i]);
        dst.push_back((*keyframe_px)[i]);
      }
      *current_px = std::move(cur);
      *keyframe_px = std::move(dst);
    }
  }
}

void RepeatSession::DetectAndMatch(const cv::Mat& grey, RepeatStep* step) {
  current_ = FrameFeatures(grey);
  MatchKeyframe(destination_, &current_px_, &destination_px_, &scene_px_);
  last_matches_ = static_cast<int>(current_px_.size());
  step->view = std::max(0, chosen_view_[static_cast<std::size_t>(destination_)]);
  step->redetected = true;
  frames_since_detect_ = 0;
}

RepeatStep RepeatSession::Stop(RepeatStep step, RepeatStatus status, const std::string& reason) {
  step.status = status;
  step.reason = reason;
  step.command = Twist2{};
  // Only completion and abort end the session; waiting is decided again every frame.
  if (status == RepeatStatus::kCompleted || status == RepeatStatus::kAborted) status_ = status;
  return step;
}

RepeatStep RepeatSession::Update(const cv::Mat& image, Timestamp t_ns,
                                 const std::optional<Pose2>& odometry) {
  odometry_ = odometry;
  frame_features_.reset();
  // At the start the robot stands at keyframe 0, where the first segment begins.
  if (!have_last_t_ && destination_ == 1) switch_odometry_ = odometry;
  RepeatStep step;
  step.destination = destination_;
  if (finished())
    return Stop(step, status_, status_ == RepeatStatus::kCompleted ? "route completed" : "aborted");
  const double dt = have_last_t_ ? std::max(0.0, ToSeconds(t_ns - last_t_ns_)) : 0.0;
  // Keyframe recovery's measure of progress: the time spent with a moving command.
  if (last_command_.v_mps != 0.0 || last_command_.omega_radps != 0.0) driven_since_switch_s_ += dt;
  driven_since_switch_m_ += std::max(0.0, last_command_.v_mps * dt);
  last_t_ns_ = t_ns;
  have_last_t_ = true;
  // Grey once: the camera check, the watch and the method all read the grey frame.
  cv::Mat grey = image;
  if (image.channels() == 3) cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  const CameraCheck camera = camera_.Check(grey, last_command_);
  if (!camera.usable()) {
    step.matches = last_matches_;
    step = Stop(step, RepeatStatus::kWaiting, camera.reason);
  } else {
    // The obstacle watch first: a blocked robot does not look for its keyframe.
    const ObstacleCheck obstacle = WatchAndDetect(grey, t_ns, dt);
    watch_unchecked_m_ = options_.obstacle.enabled ? obstacle.unchecked_m : 0.0;
    const bool started = !detour_ && obstacle.blocked && StartDetour(obstacle, grey.size());
    if (detour_) {
      // Going round it (--on-obstacle avoid) until back on the route; the obstacle that started
      // the detour is not news to it.
      step = Detouring(step, started ? ObstacleCheck{} : obstacle);
    } else if (obstacle.blocked) {
      step.matches = last_matches_;
      step = Stop(step, RepeatStatus::kBlocked, obstacle.reason);
    } else {
      // The time spent blocked is not time spent looking for features.
      if (obstacle.cleared && waiting_) waiting_since_ns_ = t_ns;
      if (obstacle.cleared && short_since_ns_) short_since_ns_ = t_ns;
      step = Decide(grey, t_ns);
      if (obstacle.creeping && step.status == RepeatStatus::kDriving) {
        // Straight ahead, slowly, until the watch has checked the ground (obstacle_watch.h).
        step.command = Twist2{options_.obstacle.CreepSpeedMps(), 0.0};
        step.reason = obstacle.reason;
      }
      step.current_px = current_px_;
      step.destination_px = destination_px_;
    }
    step.obstacle = obstacle;
  }
  frame_features_.reset();
  last_command_ = step.command;
  return step;
}

// Algorithm 1 of Kassir et al., one frame, in the stages below: the leader's next keyframe (a live
// route), tracking and matching the destination, recovery and carrying on where it no longer
// matches, waiting, the switch to the next segment (line 9), and the funnel lane (line 19).
RepeatStep RepeatSession::Decide(const cv::Mat& image, Timestamp t_ns) {
  RepeatStep step;
  step.destination = destination_;
  cv::Mat grey = image;
  if (image.channels() == 3) cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  MAPLESS_CHECK(grey.cols == route_->image_width && grey.rows == route_->image_height,
                "RepeatSession: frame is " << grey.cols << "x" << grey.rows
                                           << " but the route was taught at " << route_->image_width
                                           << "x" << route_->image_height);
  if (waiting_for_route_ && !NextTaughtKeyframe(&step)) return step;
  const bool short_long = TrackDestination(grey, t_ns, &step);
  if (HoldOrCarryOn(t_ns, short_long, &step)) return step;
  std::vector<control::FeaturePair> pairs = Pairs();
  if (SwitchSegment(grey, t_ns, &pairs, &step)) return step;
  // Line 19: control with the funnel lane.
  if (options_.controller == Controller::kSloped) {
    step.sloped = control::ComputeSlopedFunnelLane(pairs, options_.sloped);
    step.command = step.sloped.twist;
  } else {
    step.standard = control::ComputeStandardFunnelLane(pairs, options_.standard);
    step.command = step.standard.twist;
  }
  step.status = RepeatStatus::kDriving;
  return step;
}

bool RepeatSession::NextTaughtKeyframe(RepeatStep* step) {
  const int known = static_cast<int>(route_->keyframes.size());
  if (destination_ + 1 >= known) {
    previous_.release();
    current_px_.clear();
    destination_px_.clear();
    scene_px_.clear();
    if (route_->complete)
      *step = Stop(*step, RepeatStatus::kCompleted, "route completed: passed the last keyframe");
    else
      *step = Stop(*step, RepeatStatus::kWaiting,
                   "waiting for the leader: keyframe " + std::to_string(destination_) +
                       " is the last it has taught so far");
    return false;
  }
  // The leader taught the next keyframe: switch to it as at any segment switch.
  waiting_for_route_ = false;
  MarkSwitch();
  ++destination_;
  step->switched = true;
  step->destination = destination_;
  have_expected_dx_ = false;  // the robot stood still: no prediction from the last segment
  current_px_.clear();
  destination_px_.clear();
  scene_px_.clear();
  return true;
}

bool RepeatSession::TrackDestination(const cv::Mat& grey, Timestamp t_ns, RepeatStep* step) {
  // Periodic refresh (an option; see RepeatOptions::redetect_every_frames): no point tracking
  // features that are about to be replaced.
  ++frames_since_detect_;
  // Carrying on matches every frame afresh.
  const bool refresh = carry_active_ || reacquire_ ||
                       (options_.redetect_every_frames > 0 &&
                        frames_since_detect_ >= options_.redetect_every_frames);
  // Algorithm 1, lines 16-18: track the matched features inside the segment.
  if (!refresh && !previous_.empty() && !current_px_.empty()) {
    const features::KltResult tracked =
        features::TrackKlt(previous_, grey, current_px_, options_.klt);
    std::vector<cv::Point2f> cur, dst;
    for (std::size_t i = 0; i < current_px_.size(); ++i) {
      if (!tracked.ok[i]) continue;
      cur.push_back(tracked.points[i]);
      dst.push_back(destination_px_[i]);
    }
    current_px_ = std::move(cur);
    destination_px_ = std::move(dst);
    scene_px_ = current_px_;
  }
  previous_ = grey.clone();
  // Lines 20-27: too few features left, detect and match again (or refresh).
  if (static_cast<int>(current_px_.size()) < options_.min_features || refresh)
    DetectAndMatch(grey, step);
  step->matches = last_matches_;
  step->tracked = static_cast<int>(current_px_.size());
  // The destination is short of features from a frame with fewer than min_features until one
  // matches it as well as a recovered keyframe must: a few matches that come and go (the
  // landmarks' surroundings, the robot creeping a frame at a time) do not end the shortage.
  const int found = std::max(options_.recovery_min_features, options_.min_features);
  if (step->tracked < options_.min_features && !short_since_ns_) short_since_ns_ = t_ns;
  if (step->tracked >= found) short_since_ns_.reset();
  // Back on the route after a detour: the keyframe that matches best (the detour may have taken
  // the robot past the destination and more).
  if (reacquire_) {
    reacquire_ = false;
    Reacquire(step);
    step->matches = last_matches_;
    step->tracked = static_cast<int>(current_px_.size());
  }
  // Keyframe recovery, once the destination has been short for recovery_after_s (a shortage
  // that passes by itself is waited out, not skipped).
  const bool short_long = step->tracked < options_.min_features && short_since_ns_ &&
                          ToSeconds(t_ns - *short_since_ns_) >= options_.recovery_after_s;
  // While carrying on, CarryOn tries every keyframe recovery would (and farther): not twice.
  if (short_long && !carrying_ && Recover(step)) {
    step->matches = last_matches_;
    step->tracked = static_cast<int>(current_px_.size());
  }
  return short_long;
}

bool RepeatSession::HoldOrCarryOn(Timestamp t_ns, bool short_long, RepeatStep* step) {
  // Carrying on through keyframes that recovery could not find (RepeatOptions::carry_on), until
  // the destination or a following keyframe matches as well as a recovered keyframe must.
  const int found = std::max(options_.recovery_min_features, options_.min_features);
  const bool carry = carry_active_ ? step->tracked < found : short_long && !step->switched;
  if (carry) {
    if (const std::optional<Twist2> command = CarryOn(t_ns, step)) {
      step->command = *command;
      step->status = RepeatStatus::kDriving;
      return true;
    }
    step->matches = last_matches_;
    step->tracked = static_cast<int>(current_px_.size());
  }
  // The destination matches again: the funnel lane drives; carrying on resumes where it was
  // if the destination is lost again.
  if (step->tracked >= found) carry_active_ = false;
  if (step->tracked < options_.min_features) {
    // Stop while features are insufficient; abort if that lasts too long.
    if (!waiting_) {
      waiting_ = true;
      waiting_since_ns_ = t_ns;
    }
    const double waited = ToSeconds(t_ns - waiting_since_ns_);
    if (waited > options_.guided_release_s) have_expected_dx_ = false;
    if (waited > options_.abort_after_s) {
      *step = Stop(*step, RepeatStatus::kAborted,
                   "aborted: fewer than " + std::to_string(options_.min_features) +
                       " features matched keyframe " + std::to_string(destination_) + " for " +
                       std::to_string(static_cast<int>(waited)) + " s");
      return true;
    }
    *step = Stop(*step, RepeatStatus::kWaiting,
                 "stopped: only " + std::to_string(step->tracked) + " features match keyframe " +
                     std::to_string(destination_) + " (need " +
                     std::to_string(options_.min_features) + ")");
    return true;
  }
  waiting_ = false;
  expected_dx_ = MedianDx(destination_px_, current_px_);
  have_expected_dx_ = true;
  return false;
}

bool RepeatSession::SwitchSegment(const cv::Mat& grey, Timestamp t_ns,
                                  std::vector<control::FeaturePair>* pairs, RepeatStep* step) {
  // Line 9: switch to the next segment.
  step->switching = control::CheckSwitch(*pairs, options_.switch_rule);
  const bool enough = static_cast<int>(pairs->size()) >= options_.min_switch_features;
  const bool last = destination_ + 1 >= static_cast<int>(route_->keyframes.size());
  // The route's end (or every keyframe with Switching::kLocalScale): the local scale instead of
  // StdRatio (see RepeatOptions); with too few nearby pairs (a sparse view), StdRatio.
  if ((last && options_.end_by_local_scale) || options_.switching == Switching::kLocalScale) {
    std::vector<control::FeaturePoint> points;
    points.reserve(current_px_.size());
    for (std::size_t i = 0; i < current_px_.size(); ++i) {
      points.push_back(
          {current_px_[i].x, current_px_[i].y, destination_px_[i].x, destination_px_[i].y});
    }
    step->local_scale = control::MeasureLocalScale(points, options_.local_scale);
  }
  const bool by_scale = step->local_scale.ok;
  const bool condition = by_scale ? step->local_scale.ratio > options_.switch_rule.min_std_ratio &&
                                        step->switching.ed_px < options_.switch_rule.max_ed_px
                                  : step->switching.switch_now;
  switch_votes_ = (condition && enough) ? switch_votes_ + 1 : 0;
  const bool mse_says = options_.switching == Switching::kMse && mse_.Update(*pairs) && enough;
  const int confirm = last ? options_.final_confirm_frames : options_.switch_confirm_frames;
  const bool switch_now =
      options_.switching != Switching::kMse || by_scale ? switch_votes_ >= confirm : mse_says;
  if (!switch_now) return false;
  if (options_.learn) MaybeLearn(step);
  step->switched = true;
  MarkSwitch();
  ++destination_;
  mse_.Reset();
  switch_votes_ = 0;
  step->destination = destination_;
  if (destination_ >= static_cast<int>(route_->keyframes.size())) {
    destination_ = static_cast<int>(route_->keyframes.size()) - 1;
    step->destination = destination_;
    if (!route_->complete && options_.wait_for_leader) {
      waiting_for_route_ = true;
      *step = Stop(*step, RepeatStatus::kWaiting,
                   "waiting for the leader: keyframe " + std::to_string(destination_) +
                       " is the last it has taught so far");
      return true;
    }
    *step = Stop(*step, RepeatStatus::kCompleted, "route completed: passed the last keyframe");
    return true;
  }
  // Predict the displacement against the new destination: the current one against the old
  // destination, minus how far features moved from it to the new one during the teach.
  const auto& next = route_->keyframes[static_cast<std::size_t>(destination_)];
  if (!next.segment_start_px.empty())
    expected_dx_ -= MedianDx(next.segment_start_px, next.segment_end_px);
  // Lines 11-14: detect and match against the new destination.
  DetectAndMatch(grey, step);
  step->matches = last_matches_;
  step->tracked = static_cast<int>(current_px_.size());
  if (step->tracked < options_.min_features) {
    waiting_ = true;
    waiting_since_ns_ = t_ns;
    *step = Stop(*step, RepeatStatus::kWaiting,
                 "stopped: only " + std::to_string(step->tracked) + " features match keyframe " +
                     std::to_string(destination_));
    return true;
  }
  *pairs = Pairs();
  return false;
}

}  // namespace mapless::navigation
