// RepeatSession going round an obstacle on the route (issue 21, `--on-obstacle avoid`; not in
// the paper): the obstacle watch confirms something new ahead, the visual potential on its map
// picks the side, control::Detour drives round by odometry with the watch looking ahead, and the
// repeat then re-acquires its keyframe. The rest of the session is in repeat.cc.
#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>

#include "mapless/navigation/repeat.h"

namespace mapless::navigation {

bool RepeatSession::StartDetour(const ObstacleCheck& obstacle, cv::Size image) {
  const ObstacleWatchOptions& w = options_.obstacle;
  if (!w.enabled || !w.avoid || !odometry_ || detours_ >= options_.max_detours) return false;
  control::VisualPotentialOptions potential;
  potential.repulsion_gain = 2.0;  // as the visual-potential navigator's default
  // The side: Eq. 8-16 on the lower image (where the watch fits the ground; every point off the
  // ground's plane repels), the destination straight ahead (the route's direction where the
  // robot stopped). How far aside: the obstacle's extent in the image.
  const double theta =
      control::DetourAngle(obstacle.off_plane_px, image, w.fit_top, w.grid_px, 0.0, potential);
  const control::ObstacleExtent extent =
      control::MeasureObstacleExtent(obstacle.obstacle_px, obstacle.off_plane_px, image,
                                     w.region_width, w.region_top, w.region_half_width_m);
  no_ground_frames_ = 0;
  detour_.emplace(*odometry_, theta, extent, w.region_half_width_m, options_.detour);
  ++detours_;
  watch_.Resume();  // the watch goes on looking ahead while the robot goes round
  return true;
}

RepeatStep RepeatSession::Detouring(RepeatStep step, const ObstacleCheck& obstacle) {
  step.matches = last_matches_;
  if (!odometry_) {
    // The odometry stopped: the detour cannot go on.
    detour_.reset();
    return Stop(step, RepeatStatus::kBlocked,
                "going round an obstacle: no odometry on this frame: stopped");
  }
  control::AheadView ahead = control::AheadView::kUnknown;
  // The ground ahead not found on two compared frames in a row: a wall or something large
  // fills the view (the watch cannot measure it, the detour must not drive into it).
  no_ground_frames_ = obstacle.no_ground ? no_ground_frames_ + 1 : 0;
  if (obstacle.blocked || no_ground_frames_ >= 2) {
    ahead = control::AheadView::kBlocked;
    watch_.Resume();
  } else if (obstacle.observed) {
    ahead = obstacle.blocked_fraction > options_.obstacle.min_blocked_fraction
                ? control::AheadView::kSuspect
                : control::AheadView::kFree;
  }
  step.command = detour_->Command(*odometry_, ahead, RouteSpeed());
  const control::DetourPhase phase = detour_->phase();
  std::ostringstream why;
  why << "going round an obstacle by the " << (detour_->side() > 0.0 ? "left" : "right") << ": "
      << control::DetourPhaseName(phase) << " (" << std::lround(100.0 * detour_->offset_m())
      << " cm off the route)";
  if (phase == control::DetourPhase::kFailed) {
    detour_.reset();
    detours_ = options_.max_detours;  // no more tries at this destination: stop and wait
    return Stop(step, RepeatStatus::kBlocked, why.str() + ": no way round: stopped");
  }
  step.avoiding = true;
  step.status = RepeatStatus::kDriving;
  step.reason = why.str();
  if (phase == control::DetourPhase::kDone) {
    detour_.reset();
    watch_.Resume();
    reacquire_ = true;
    waiting_ = false;
    short_since_ns_.reset();
  }
  return step;
}

void RepeatSession::Reacquire(RepeatStep* step) {
  const int last = std::min(destination_ + options_.carry_on_keyframes,
                            static_cast<int>(route_->keyframes.size()) - 1);
  int best = destination_;
  std::vector<cv::Point2f> best_cur = current_px_, best_dst = destination_px_,
                           best_scene = scene_px_;
  for (int k = destination_ + 1; k <= last; ++k) {
    std::vector<cv::Point2f> cur, dst, scene;
    MatchKeyframe(k, &cur, &dst, &scene);
    if (cur.size() > best_cur.size()) {
      best = k;
      best_cur = std::move(cur);
      best_dst = std::move(dst);
      best_scene = std::move(scene);
    }
  }
  const int found = std::max(options_.recovery_min_features, options_.min_features);
  if (best != destination_ && static_cast<int>(best_cur.size()) >= found)
    SwitchTo(best, std::move(best_cur), std::move(best_dst), std::move(best_scene), step);
}

}  // namespace mapless::navigation
