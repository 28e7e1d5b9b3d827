#include "mapless/sim/driver.h"

#include <algorithm>
#include <cmath>

#include "mapless/core/check.h"

namespace mapless::sim {

void DriverOptions::Validate() const {
  MAPLESS_CHECK(lookahead_m > 0.0,
                "DriverOptions.lookahead_m = " << lookahead_m << "; must be > 0");
  MAPLESS_CHECK(goal_tolerance_m > 0.0,
                "DriverOptions.goal_tolerance_m = " << goal_tolerance_m << "; must be > 0");
  MAPLESS_CHECK(rotate_speed_radps > 0.0,
                "DriverOptions.rotate_speed_radps = " << rotate_speed_radps << "; must be > 0");
  MAPLESS_CHECK(decel_mps2 > 0.0, "DriverOptions.decel_mps2 = " << decel_mps2 << "; must be > 0");
}

ScriptedDriver::ScriptedDriver(const Pose2& start, const std::vector<PathStep>& path,
                               double default_speed_mps, DriverOptions options)
    : options_(options) {
  options_.Validate();
  Eigen::Vector2d at(start.x_m, start.y_m);
  for (const PathStep& step : path) {
    if (step.kind == PathStep::Kind::kRotate) {
      Leg leg;
      leg.rotate = true;
      leg.rotate_rad = step.rotate_rad;
      legs_.push_back(leg);
      continue;
    }
    if (legs_.empty() || legs_.back().rotate) {
      Leg leg;
      leg.points.push_back(at);
      legs_.push_back(leg);
    }
    Leg& leg = legs_.back();
    if ((step.target - leg.points.back()).norm() < 1e-6) continue;
    leg.points.push_back(step.target);
    leg.speeds.push_back(step.speed_mps > 0.0 ? step.speed_mps : default_speed_mps);
    at = step.target;
  }
  // Drop polylines with no segment (a path that only rotates).
  legs_.erase(std::remove_if(legs_.begin(), legs_.end(),
                             [](const Leg& l) { return !l.rotate && l.points.size() < 2; }),
              legs_.end());
}

Twist2 ScriptedDriver::Update(const Pose2& pose) {
  while (!done()) {
    const Twist2 cmd = legs_[leg_].rotate ? Rotate(pose) : FollowPolyline(pose);
    if (leg_started_) return cmd;
    // The leg just finished: start the next one on the same pose.
  }
  return Twist2{};
}

Twist2 ScriptedDriver::Rotate(const Pose2& pose) {
  const Leg& leg = legs_[leg_];
  if (!leg_started_) {
    leg_started_ = true;
    rotate_target_rad_ = pose.theta_rad + leg.rotate_rad;
  }
  const double err = WrapAngle(rotate_target_rad_ - pose.theta_rad);
  if (std::abs(err) < options_.rotate_tolerance_rad) {
    ++leg_;
    leg_started_ = false;
    return Twist2{};
  }
  const double omega =
      std::clamp(2.0 * err, -options_.rotate_speed_radps, options_.rotate_speed_radps);
  return Twist2{0.0, std::abs(omega) < 0.08 ? std::copysign(0.08, err) : omega};
}

Twist2 ScriptedDriver::FollowPolyline(const Pose2& pose) {
  const Leg& leg = legs_[leg_];
  if (!leg_started_) {
    leg_started_ = true;
    progress_m_ = 0.0;
    aligning_ = true;
  }
  // Cumulative lengths.
  std::vector<double> cum(leg.points.size(), 0.0);
  for (std::size_t i = 1; i < leg.points.size(); ++i) {
    cum[i] = cum[i - 1] + (leg.points[i] - leg.points[i - 1]).norm();
  }
  const double total = cum.back();
  const Eigen::Vector2d p(pose.x_m, pose.y_m);
  // Project the robot on the polyline near the current progress (never backwards).
  double best_d = 1e30;
  double best_s = progress_m_;
  for (std::size_t i = 0; i + 1 < leg.points.size(); ++i) {
    if (cum[i + 1] < progress_m_ - 0.5) continue;
    if (cum[i] > progress_m_ + 1.0) break;
    const Eigen::Vector2d a = leg.points[i];
    const Eigen::Vector2d ab = leg.points[i + 1] - a;
    const double t = std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
    const double d = (a + t * ab - p).norm();
    if (d < best_d) {
      best_d = d;
      best_s = cum[i] + t * ab.norm();
    }
  }
  progress_m_ = std::max(progress_m_, best_s);
  const Eigen::Vector2d end = leg.points.back();
  const double remaining = std::max(total - progress_m_, (end - p).norm());
  // A leg ends at its last point once the robot has come most of the way along it (a closed loop
  // passes its end point near the start, too).
  const bool near_end_of_leg = progress_m_ >= total - std::max(1.0, 2.0 * options_.lookahead_m);
  if (near_end_of_leg &&
      ((end - p).norm() < options_.goal_tolerance_m ||
       (progress_m_ >= total - 1e-6 && (end - p).norm() < 3.0 * options_.goal_tolerance_m))) {
    ++leg_;
    leg_started_ = false;
    return Twist2{};
  }
  auto point_at = [&](double s) {
    s = std::clamp(s, 0.0, total);
    std::size_t i = 0;
    while (i + 2 < leg.points.size() && cum[i + 1] < s) ++i;
    const double seg = cum[i + 1] - cum[i];
    const double t = seg > 0.0 ? (s - cum[i]) / seg : 0.0;
    return Eigen::Vector2d(leg.points[i] + t * (leg.points[i + 1] - leg.points[i]));
  };
  std::size_t seg = 0;
  while (seg + 2 < leg.points.size() && cum[seg + 1] < progress_m_) ++seg;
  const double speed = leg.speeds[seg];
  // Look-ahead point; near the end aim at the end itself.
  const Eigen::Vector2d target =
      remaining < options_.lookahead_m ? end : point_at(progress_m_ + options_.lookahead_m);
  const Eigen::Vector2d d = target - p;
  const double c = std::cos(pose.theta_rad);
  const double s = std::sin(pose.theta_rad);
  const double lx = c * d.x() + s * d.y();
  const double ly = -s * d.x() + c * d.y();
  const double alpha = std::atan2(ly, lx);
  const double dist = std::max(d.norm(), 1e-3);
  // Turn in place while the path is far off the heading (start of a leg, or after a rotation).
  if (std::abs(alpha) > options_.turn_in_place_above_rad || (aligning_ && std::abs(alpha) > 0.1)) {
    return Twist2{
        0.0, std::clamp(2.0 * alpha, -options_.rotate_speed_radps, options_.rotate_speed_radps)};
  }
  aligning_ = false;
  double v = std::min(speed, std::sqrt(2.0 * options_.decel_mps2 * remaining));
  v = std::max(v, 0.05);
  const double curvature = 2.0 * std::sin(alpha) / dist;
  return Twist2{v, v * curvature};
}

}  // namespace mapless::sim
