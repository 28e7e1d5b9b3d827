// The appearance follower's steering, its recovery of route images whose view has changed and
// carrying on along the leader's odometry (issue 21; AppearanceFollowerOptions::recover_images,
// carry_on). The follower itself is in appearance.cc.
#include <algorithm>
#include <cmath>

#include "mapless/navigation/appearance.h"

namespace mapless::navigation {

bool AppearanceFollower::SteerTowards(const std::vector<int>& targets, const cv::Mat& low,
                                      const route::AppearanceRoute& route,
                                      FollowerStep* step) const {
  // Each target by its route image first; where none fits, by the learned view of each that is
  // nearest the current image (appearance_experiences.h).
  std::vector<std::pair<int, int>> tries;  // (target, column)
  for (const int target : targets)
    if (target >= 0 && target < route.size()) tries.emplace_back(target, target);
  if (route.has_views()) {
    for (const int target : targets) {
      if (target < 0 || target >= route.size()) continue;
      const int column = NearestColumnOf(route, target);
      if (column != target) tries.emplace_back(target, column);
    }
  }
  for (const auto& [target, column] : tries) {
    const appearance::SubWindowEigenspace& windows = route.WindowsOf(column);
    std::vector<control::WindowCorrespondence> matches;
    for (const appearance::SubWindowMatch& m :
         appearance::MatchSubWindows(windows, low, options_.windows)) {
      matches.push_back({m.query, m.stored});
    }
    step->target = target;
    step->steering = control::ComputeSubWindowSteering(matches, windows.windows(),
                                                       options_.windows.step_px, options_.steering);
    if (!step->steering.ok) continue;
    const std::vector<int> columns = route.ColumnsOf(target);
    step->target_view =
        static_cast<int>(std::find(columns.begin(), columns.end(), column) - columns.begin());
    if (column >= route.size()) {
      // A learned view: its shift chained to the taught image (appearance_experiences.h).
      step->steering.shift_px += route.OffsetOf(column);
      step->steering.shift_windows = step->steering.shift_px / options_.windows.step_px;
      step->steering.twist = control::SteeringTwist(step->steering.shift_px, options_.steering);
    }
    if (used_views_.size() < static_cast<std::size_t>(route.size()))
      used_views_.resize(static_cast<std::size_t>(route.size()), -1);
    used_views_[static_cast<std::size_t>(target)] = step->target_view;
    return true;
  }
  return false;
}

bool AppearanceFollower::Recover(int ahead, const cv::Mat& low, const route::AppearanceRoute& route,
                                 FollowerStep* step) const {
  if (options_.recover_images <= 0 || !options_.use_markov) return false;
  // Route image j is the one ahead from place j - lookahead_images: try them by the belief
  // there, the nearer first among equals.
  const Eigen::VectorXd& belief = markov_.belief();
  std::vector<std::pair<double, int>> order;
  for (int j = ahead + 2; j <= std::min(ahead + 1 + options_.recover_images, route.size() - 1);
       ++j) {
    const int place = j - options_.lookahead_images;
    const double p = place >= 0 && place < belief.size() ? belief(place) : 0.0;
    order.emplace_back(-p, j);
  }
  std::stable_sort(order.begin(), order.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<int> targets;
  for (const auto& [p, j] : order) targets.push_back(j);
  FollowerStep trial = *step;
  if (!SteerTowards(targets, low, route, &trial)) return false;
  step->target = trial.target;
  step->steering = trial.steering;
  return true;
}

double AppearanceFollower::HeadingOffset(const Pose2& odometry, const Pose2& leader) const {
  if (heading_offsets_.empty()) return WrapAngle(odometry.theta_rad - leader.theta_rad);
  double s = 0.0;
  double c = 0.0;
  for (const double a : heading_offsets_) {
    s += std::sin(a);
    c += std::cos(a);
  }
  return std::atan2(s, c);
}

std::optional<Twist2> AppearanceFollower::CarryOn(const Pose2& odometry,
                                                  const route::AppearanceRoute& route,
                                                  FollowerStep* step) {
  if (!options_.use_markov || options_.carry_on.max_distance_m <= 0.0 || carry_given_up_ ||
      step->index < 0 || step->index >= route.size() - 1) {
    return std::nullopt;
  }
  if (!carrying_) {
    // From the follower's place on the route (the belief's), through the leader's poses of the
    // route images after it, taken as where the follower is now.
    // The heading: the leader's, turned by the mean difference over the last frames of following
    // (the current heading alone is often already turning aside as the fits go wrong).
    std::vector<Pose2> taught;
    for (int j = step->index + 1; j < route.size(); ++j)
      taught.push_back(route.images[static_cast<std::size_t>(j)]->odometry);
    const Pose2& from = route.images[static_cast<std::size_t>(step->index)]->odometry;
    const double offset = HeadingOffset(odometry, from);
    carrying_.emplace(std::move(taught), from,
                      Pose2{odometry.x_m, odometry.y_m, WrapAngle(from.theta_rad + offset)},
                      options_.carry_on);
  }
  const std::optional<Twist2> command =
      carrying_->Command(odometry, options_.steering.max_speed_mps);
  if (!command) {
    carrying_.reset();
    carry_given_up_ = true;
    return std::nullopt;
  }
  step->carrying_on = true;
  step->reason = "carrying on: no route image ahead of " + std::to_string(step->index) +
                 " fits; driving the leader's odometry (" +
                 std::to_string(static_cast<int>(100.0 * carrying_->driven_m())) + " cm of " +
                 std::to_string(static_cast<int>(100.0 * options_.carry_on.max_distance_m)) +
                 " cm)";
  return command;
}

}  // namespace mapless::navigation
