// RepeatSession when its destination keyframe cannot be matched (issue 21; not in the paper):
// keyframe recovery (the following keyframes, within reach) and carrying on along the taught
// odometry. The rest of the session is in repeat.cc.
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "mapless/navigation/repeat.h"

namespace mapless::navigation {

double RepeatSession::RouteLeftM() const {
  const auto& kfs = route_->keyframes;
  const int n = static_cast<int>(kfs.size());
  if (!route_->complete || n == 0) return std::numeric_limits<double>::infinity();
  double left = 0.0;
  for (int k = std::max(0, destination_ - 1); k + 1 < n; ++k) {
    const auto& a = kfs[static_cast<std::size_t>(k)].odometry;
    const auto& b = kfs[static_cast<std::size_t>(k) + 1].odometry;
    if (!a || !b) return std::numeric_limits<double>::infinity();
    left += std::hypot(b->x_m - a->x_m, b->y_m - a->y_m);
    // Beyond what the watch can see the answer makes no difference: mid-route this stops after a
    // few keyframes instead of summing the rest of a long route every frame.
    if (left - driven_since_switch_m_ > options_.obstacle.region_far_m)
      return std::numeric_limits<double>::infinity();
  }
  return std::max(0.0, left - driven_since_switch_m_) + options_.route_end_margin_m;
}

void RepeatSession::MarkSwitch() {
  driven_since_switch_s_ = 0.0;
  driven_since_switch_m_ = 0.0;
  switch_odometry_ = odometry_;
  carrying_.reset();
  carry_active_ = false;
  carried_this_destination_ = false;
  short_since_ns_.reset();
  detours_ = 0;
}

bool RepeatSession::SwitchToMatching(int first, int last, Reach reach, RepeatStep* step) {
  const auto& kfs = route_->keyframes;
  const auto taught_at = [&](int k) { return ToSeconds(kfs[static_cast<std::size_t>(k)].t_ns); };
  const auto& from = kfs[static_cast<std::size_t>(std::max(0, destination_ - 1))].odometry;
  const auto taught_m = [&](int k) {
    const auto& to = kfs[static_cast<std::size_t>(k)].odometry;
    return from && to ? std::hypot(to->x_m - from->x_m, to->y_m - from->y_m)
                      : std::numeric_limits<double>::infinity();
  };
  last = std::min(last, static_cast<int>(kfs.size()) - 1);
  for (int k = first; k <= last; ++k) {
    if (reach.taught_s >= 0.0 && taught_at(k - 1) - taught_at(destination_) > reach.taught_s) break;
    if (reach.taught_m >= 0.0 && k - 1 > destination_ && taught_m(k - 1) > reach.taught_m) break;
    std::vector<cv::Point2f> cur, dst, scene;
    MatchKeyframe(k, &cur, &dst, &scene);
    if (static_cast<int>(cur.size()) <
        std::max(options_.recovery_min_features, options_.min_features)) {
      continue;
    }
    SwitchTo(k, std::move(cur), std::move(dst), std::move(scene), step);
    return true;
  }
  return false;
}

void RepeatSession::SwitchTo(int k, std::vector<cv::Point2f> current_px,
                             std::vector<cv::Point2f> keyframe_px,
                             std::vector<cv::Point2f> scene_px, RepeatStep* step) {
  step->recovered_from = destination_;
  step->switched = true;
  destination_ = k;
  step->destination = k;
  current_px_ = std::move(current_px);
  destination_px_ = std::move(keyframe_px);
  scene_px_ = std::move(scene_px);
  last_matches_ = static_cast<int>(current_px_.size());
  mse_.Reset();
  switch_votes_ = 0;
  MarkSwitch();
}

double RepeatSession::RouteSpeed() const {
  return options_.controller == Controller::kSloped ? options_.sloped.max_speed_mps
                                                    : options_.standard.forward_speed_mps;
}

bool RepeatSession::Recover(RepeatStep* step) {
  if (options_.recovery_keyframes <= 0 || !step->redetected) return false;
  // Keyframe k as the destination puts the robot past keyframe k - 1: the keyframe after the
  // unmatched one always qualifies (the robot is somewhere before the unmatched keyframe, the
  // next one is the next place it can head for), those farther only as far as the robot may
  // have driven since the last switch.
  Reach reach;
  reach.taught_s = options_.recovery_time_factor * driven_since_switch_s_;
  return SwitchToMatching(destination_ + 1, destination_ + options_.recovery_keyframes, reach,
                          step);
}

std::optional<Twist2> RepeatSession::CarryOn(Timestamp t_ns, RepeatStep* step) {
  if (options_.carry_on.max_distance_m <= 0.0 || !odometry_ || !step->redetected) return {};
  const auto& kfs = route_->keyframes;
  const int last =
      std::min(destination_ + options_.carry_on_keyframes, static_cast<int>(kfs.size()) - 1);
  if (!carrying_) {
    // From the place of the last switch (keyframe destination - 1), through the taught poses of
    // the unmatched keyframe and those after it; not again once given up at this destination.
    const auto& from = kfs[static_cast<std::size_t>(destination_ - 1)];
    if (carried_this_destination_ || !switch_odometry_ || !from.odometry) return {};
    std::vector<Pose2> taught;
    for (int k = destination_; k <= last; ++k) {
      const auto& kf = kfs[static_cast<std::size_t>(k)];
      if (!kf.odometry) break;
      taught.push_back(*kf.odometry);
    }
    if (taught.empty()) return {};
    carrying_.emplace(std::move(taught), *from.odometry, *switch_odometry_, options_.carry_on);
  }
  carry_active_ = true;
  // A following keyframe that matches ends it: the funnel lane takes over.
  Reach reach;
  reach.taught_m =
      options_.carry_on_reach_factor *
      std::hypot(odometry_->x_m - switch_odometry_->x_m, odometry_->y_m - switch_odometry_->y_m);
  if (SwitchToMatching(destination_ + 1, last, reach, step)) return {};
  // Blind twice over is too much: without the route's view, the ground ahead must be seen.
  const bool unseen = watch_unchecked_m_ > options_.carry_on_unchecked_m;
  const std::optional<Twist2> command =
      unseen ? std::nullopt : carrying_->Command(*odometry_, RouteSpeed());
  if (!command) {
    // Given up: the robot stops and the abort countdown starts afresh; no second try at this
    // destination.
    carrying_.reset();
    carry_active_ = false;
    carried_this_destination_ = true;
    waiting_since_ns_ = t_ns;
    return {};
  }
  step->carrying_on = true;
  step->reason = "carrying on: keyframe " + std::to_string(destination_) +
                 " does not match; driving the taught path by odometry (" +
                 std::to_string(static_cast<int>(100.0 * carrying_->driven_m())) + " cm of " +
                 std::to_string(static_cast<int>(100.0 * options_.carry_on.max_distance_m)) +
                 " cm)";
  return command;
}

}  // namespace mapless::navigation
