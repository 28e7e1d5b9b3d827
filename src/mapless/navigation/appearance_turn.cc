// The appearance follower's taught turns in place (AppearanceFollowerOptions::turn_in_place_*;
// not in the paper). The follower itself is in appearance.cc.
#include <algorithm>
#include <cmath>
#include <sstream>

#include "mapless/navigation/appearance.h"

namespace mapless::navigation {

double AppearanceFollower::LeaderCurvature(const route::AppearanceRoute& route, int from, int to) {
  if (from < 0 || to <= from || to >= route.size()) return 0.0;
  double turned = 0.0;
  for (int i = from; i < to; ++i) {
    turned += WrapAngle(route.images[static_cast<std::size_t>(i + 1)]->odometry.theta_rad -
                        route.images[static_cast<std::size_t>(i)]->odometry.theta_rad);
  }
  const double driven = route.images[static_cast<std::size_t>(to)]->distance_m -
                        route.images[static_cast<std::size_t>(from)]->distance_m;
  return driven < 0.05 ? 0.0 : turned / driven;
}

std::optional<Twist2> AppearanceFollower::TurnInPlace(const Pose2& odometry,
                                                      const route::AppearanceRoute& route,
                                                      FollowerStep* step) {
  const int n = route.size();
  const auto image = [&](int i) -> const route::AppearanceRouteImage& {
    return *route.images[static_cast<std::size_t>(i)];
  };
  if (!turn_.active) {
    const int from = step->index;
    if (from < 0 || from <= turn_.through || from >= n - 1) return std::nullopt;
    // The leader's heading change over the images taken within turn_in_place_max_m of this one
    // (signed steps, so that a turn of more than half a circle adds up), up to the first image
    // beyond them: its heading is the one the leader drove on with.
    double turned = 0.0;
    int last = from;
    while (last + 1 < n &&
           image(last + 1).distance_m - image(from).distance_m <= options_.turn_in_place_max_m) {
      turned += WrapAngle(image(last + 1).odometry.theta_rad - image(last).odometry.theta_rad);
      ++last;
    }
    if (last + 1 < n) {
      turned += WrapAngle(image(last + 1).odometry.theta_rad - image(last).odometry.theta_rad);
      ++last;
    }
    if (std::abs(turned) < options_.turn_in_place_min_rad) return std::nullopt;
    // The follower's heading offset to the leader at this place, as carrying on takes it.
    const double offset = HeadingOffset(odometry, image(from).odometry);
    turn_.active = true;
    turn_.through = last;
    // Target: this place's heading plus the offset, turned as the leader turned (not wrapped).
    turn_.target_theta_rad =
        odometry.theta_rad +
        WrapAngle(image(from).odometry.theta_rad + offset - odometry.theta_rad) + turned;
    turn_.unwrapped_theta_rad = odometry.theta_rad;
    turn_.last_theta_rad = odometry.theta_rad;
  }
  // The heading turned so far, unwrapped from frame to frame.
  turn_.unwrapped_theta_rad += WrapAngle(odometry.theta_rad - turn_.last_theta_rad);
  turn_.last_theta_rad = odometry.theta_rad;
  const double error = turn_.target_theta_rad - turn_.unwrapped_theta_rad;
  if (std::abs(error) <= options_.turn_in_place_tolerance_rad) {
    turn_.active = false;
    heading_offsets_.clear();  // the offset was measured before the turn
    return std::nullopt;
  }
  const double rate = options_.turn_in_place_rate_radps;
  std::ostringstream why;
  why.precision(0);
  why << std::fixed << "turning in place as the leader did at route image " << step->index << " ("
      << error * 180.0 / 3.141592653589793 << " degrees to go)";
  step->reason = why.str();
  // Slower near the target, so that the last frame does not overshoot the tolerance.
  return Twist2{0.0, std::clamp(2.0 * error, -rate, rate)};
}

}  // namespace mapless::navigation
