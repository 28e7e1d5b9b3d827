#include "mapless/control/detour.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "mapless/core/check.h"

namespace mapless::control {

void DetourOptions::Validate() const {
  MAPLESS_CHECK(turn_out_min_rad > 0.0 && turn_out_min_rad <= turn_out_max_rad &&
                    turn_out_max_rad < 0.5 * M_PI,
                "DetourOptions.turn_out_min_rad/turn_out_max_rad = "
                    << turn_out_min_rad << "/" << turn_out_max_rad
                    << "; must be 0 < min <= max < pi/2");
  MAPLESS_CHECK(back_off_m >= 0.0, "DetourOptions.back_off_m = " << back_off_m << "; must be >= 0");
  MAPLESS_CHECK(first_step_m > 0.0 && step_m > 0.0 && margin_m >= 0.0,
                "DetourOptions: first_step_m and step_m must be > 0, margin_m >= 0");
  MAPLESS_CHECK(max_offset_m >= first_step_m,
                "DetourOptions.max_offset_m = " << max_offset_m << "; must be >= first_step_m");
  MAPLESS_CHECK(look_max_m > 0.0, "DetourOptions.look_max_m = " << look_max_m << "; must be > 0");
  MAPLESS_CHECK(
      look_speed_fraction > 0.0 && look_speed_fraction <= 1.0,
      "DetourOptions.look_speed_fraction = " << look_speed_fraction << "; must be in (0, 1]");
  MAPLESS_CHECK(pass_m > 0.0 && lookahead_m > 0.0 && rejoined_m > 0.0,
                "DetourOptions: pass_m, lookahead_m and rejoined_m must be > 0");
  MAPLESS_CHECK(aligned_rad > 0.0 && max_omega_radps > 0.0,
                "DetourOptions: aligned_rad and max_omega_radps must be > 0");
}

const char* DetourPhaseName(DetourPhase phase) {
  switch (phase) {
    case DetourPhase::kBackOff:
      return "backing off";
    case DetourPhase::kTurnOut:
      return "turning out";
    case DetourPhase::kStepAside:
      return "stepping aside";
    case DetourPhase::kTurnBack:
      return "turning back parallel";
    case DetourPhase::kLook:
      return "looking ahead";
    case DetourPhase::kPass:
      return "passing";
    case DetourPhase::kRejoin:
      return "rejoining the route";
    case DetourPhase::kDone:
      return "done";
    case DetourPhase::kFailed:
      return "failed";
  }
  return "?";
}

double DetourAngle(const std::vector<cv::Point2f>& obstacle_px, cv::Size image, double top_fraction,
                   double point_radius_px, double theta_d_rad,
                   const VisualPotentialOptions& options) {
  MAPLESS_CHECK(image.width > 0 && image.height > 0 && top_fraction >= 0.0 && top_fraction < 1.0,
                "DetourAngle: bad image size or top fraction");
  const int top = static_cast<int>(std::lround(top_fraction * image.height));
  const cv::Size size(image.width, image.height - top);
  // d(x, y): the ground (255) except around the obstacle points (0).
  cv::Mat d(size, CV_8UC1, cv::Scalar(255));
  const int r = std::max(1, static_cast<int>(std::lround(point_radius_px)));
  for (const cv::Point2f& p : obstacle_px) {
    cv::circle(d, cv::Point(static_cast<int>(p.x), static_cast<int>(p.y) - top), r, cv::Scalar(0),
               cv::FILLED);
  }
  // The pure planar flows as the paper's downward-looking camera sees them (unit magnitude,
  // uniform): advancing, the ground streams down the image; turning left, it moves right. (A
  // level camera's translational flow diverges from the horizon's centre; its mean over the
  // ground left free by an obstacle on one side points to that side, towards the obstacle, and
  // outweighed the repulsion in the unit test. The uniform field leaves the side to Eq. 8-10.)
  const cv::Mat ut(size, CV_32FC2, cv::Scalar(0.0f, 1.0f));
  const cv::Mat ur(size, CV_32FC2, cv::Scalar(1.0f, 0.0f));
  const cv::Mat desired = DesiredFlow(ut, ur, theta_d_rad);
  const cv::Mat repulsion = RepulsionField(d, options);
  const cv::Mat potential = PotentialField(d, repulsion, desired, options);
  return CommandFromForce(ControlForce(potential), options).theta_rad;
}

ObstacleExtent MeasureObstacleExtent(const std::vector<cv::Point2f>& region_px,
                                     const std::vector<cv::Point2f>& off_plane_px, cv::Size image,
                                     double region_width_fraction, double region_top_fraction,
                                     double half_width_m, double gap_m) {
  const double cx = 0.5 * image.width;
  // The strip's half-width in pixels at the bottom row.
  const double half_px = 0.5 * region_width_fraction * image.width;
  const auto lateral = [&](const cv::Point2f& p) { return -(p.x - cx) / half_px * half_width_m; };
  // Lateral positions of the points in the region's rows, sorted, split where neighbours are
  // more than gap_m apart: the clusters holding region points are the obstacle.
  std::vector<std::pair<double, bool>> points;  // lateral, from the region
  const double top = region_top_fraction * image.height;
  for (const cv::Point2f& p : region_px) points.emplace_back(lateral(p), true);
  for (const cv::Point2f& p : off_plane_px) {
    if (p.y >= top) points.emplace_back(lateral(p), false);
  }
  std::sort(points.begin(), points.end());
  ObstacleExtent e;
  std::size_t i = 0;
  while (i < points.size()) {
    std::size_t j = i;
    bool region = points[i].second;
    while (j + 1 < points.size() && points[j + 1].first <= points[j].first + gap_m) {
      ++j;
      region = region || points[j].second;
    }
    if (region) {
      e.right_m = e.found ? std::min(e.right_m, points[i].first) : points[i].first;
      e.left_m = e.found ? std::max(e.left_m, points[j].first) : points[j].first;
      e.found = true;
    }
    i = j + 1;
  }
  return e;
}

Detour::Detour(const Pose2& stopped_at, double theta_rad, const ObstacleExtent& extent,
               double half_width_m, DetourOptions options)
    : origin_(stopped_at), options_(options) {
  options_.Validate();
  MAPLESS_CHECK(half_width_m > 0.0, "Detour: half_width_m = " << half_width_m << "; must be > 0");
  turn_out_rad_ =
      std::clamp(std::abs(theta_rad), options_.turn_out_min_rad, options_.turn_out_max_rad);
  // Clear of the obstacle's side by the strip's half-width (the robot's and its margin) and a
  // margin, on the side the force points to.
  side_ = theta_rad >= 0.0 ? 1.0 : -1.0;
  offset_m_ = FirstOffset(extent, half_width_m, side_);
  other_side_offset_m_ = FirstOffset(extent, half_width_m, -side_);
  if (offset_m_ > options_.max_offset_m) phase_ = DetourPhase::kFailed;
}

double Detour::FirstOffset(const ObstacleExtent& extent, double half_width_m, double side) const {
  // The obstacle stands in the watch's strip, somewhere: its side reaches at least the strip's
  // edge unless the image shows it reaching further (its points near an edge are few and often
  // missed: one measured 0.19 m short of the box's edge, from 6 points).
  const double beyond =
      std::max(half_width_m, extent.found ? (side > 0.0 ? extent.left_m : -extent.right_m) : 0.0);
  return std::max(options_.first_step_m, beyond + half_width_m + options_.margin_m);
}

Twist2 Detour::TurnTo(double heading_rad, double now_rad) const {
  // Proportional near the target (2.5 /s, at least 0.1 rad/s), so a frame's turn cannot
  // overshoot the alignment tolerance.
  const double error = WrapAngle(heading_rad - now_rad);
  const double rate = std::clamp(2.5 * std::abs(error), 0.1, options_.max_omega_radps);
  return {0.0, std::copysign(rate, error)};
}

Twist2 Detour::Pursue(const Pose2& local, double x_m, double y_m, double speed_mps) const {
  double x = 0.0;
  double y = 0.0;
  local.Inverse().Apply(x_m, y_m, &x, &y);
  const double d2 = std::max(1e-6, x * x + y * y);
  return {speed_mps, std::clamp(2.0 * speed_mps * y / d2, -options_.max_omega_radps,
                                options_.max_omega_radps)};
}

void Detour::StepFurther(double step_m) {
  offset_m_ += step_m;
  phase_ = offset_m_ > options_.max_offset_m ? DetourPhase::kFailed : DetourPhase::kTurnOut;
}

Twist2 Detour::Command(const Pose2& now, AheadView ahead, double speed_mps) {
  const Pose2 local = origin_.Inverse() * now;  // in the line's frame
  const double along = local.x_m;
  const double off = side_ * local.y_m;  // towards the chosen side
  const double heading = WrapAngle(local.theta_rad);
  // Each phase either returns this frame's command or hands over to the next one at once.
  for (int guard = 0; guard < 8; ++guard) {
    switch (phase_) {
      case DetourPhase::kBackOff:
        // Straight back along the line (the heading is the line's: the robot has not turned).
        if (along > -options_.back_off_m) return {-options_.look_speed_fraction * speed_mps, 0.0};
        phase_ = DetourPhase::kTurnOut;
        break;
      case DetourPhase::kTurnOut: {
        const double target = side_ * turn_out_rad_;
        if (std::abs(WrapAngle(target - heading)) > options_.aligned_rad)
          return TurnTo(target, heading);
        phase_ = DetourPhase::kStepAside;
        break;
      }
      case DetourPhase::kStepAside:
        // Something in the way of the step itself (a wall the turn now faces): no way round on
        // this side. The other side once, from here (the robot is still short of the obstacle:
        // it backed off and steps aside steeply); then the detour fails.
        if (ahead == AheadView::kBlocked) {
          if (tried_other_side_ || other_side_offset_m_ > options_.max_offset_m) {
            phase_ = DetourPhase::kFailed;
            break;
          }
          tried_other_side_ = true;
          side_ = -side_;
          offset_m_ = other_side_offset_m_;
          look_after_step_ = true;
          phase_ = DetourPhase::kTurnOut;
          break;
        }
        if (off < offset_m_) return {speed_mps, 0.0};
        phase_ = DetourPhase::kTurnBack;
        break;
      case DetourPhase::kTurnBack:
        if (std::abs(heading) > options_.aligned_rad) return TurnTo(0.0, heading);
        phase_ = look_after_step_ ? DetourPhase::kLook : DetourPhase::kPass;
        look_start_ = now;
        break;
      case DetourPhase::kLook:
        // Blocked, or not seen within look_max_m (not known to be free): a step further aside.
        if (ahead == AheadView::kBlocked || ahead == AheadView::kSuspect ||
            now.DistanceTo(look_start_) >= options_.look_max_m) {
          StepFurther(options_.step_m);
          break;
        }
        if (ahead == AheadView::kFree) {
          look_after_step_ = false;
          phase_ = DetourPhase::kPass;
          break;
        }
        return {options_.look_speed_fraction * speed_mps, 0.0};
      case DetourPhase::kPass:
        if (ahead == AheadView::kBlocked) {
          look_after_step_ = true;
          StepFurther(options_.step_m);
          break;
        }
        if (along < options_.pass_m)
          return Pursue(local, along + options_.lookahead_m, side_ * offset_m_, speed_mps);
        phase_ = DetourPhase::kRejoin;
        break;
      case DetourPhase::kRejoin:
        if (ahead == AheadView::kBlocked) {
          phase_ = DetourPhase::kFailed;
          break;
        }
        if (std::abs(off) > options_.rejoined_m)
          return Pursue(local, along + options_.lookahead_m, 0.0, speed_mps);
        phase_ = DetourPhase::kDone;
        break;
      case DetourPhase::kDone:
      case DetourPhase::kFailed:
        return {};
    }
  }
  return {};
}

}  // namespace mapless::control
