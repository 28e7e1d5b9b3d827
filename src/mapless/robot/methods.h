// The three methods of mapless behind the common face of method.h.
#pragma once

#include <Eigen/Core>
#include <functional>
#include <memory>
#include <optional>

#include "mapless/robot/method.h"
#include "mapless/route/appearance_route.h"
#include "mapless/route/route.h"

namespace mapless::robot {

// Visual teach & repeat with funnel lanes (Algorithm 1 of Kassir et al.).
class RepeatMethod : public Method {
 public:
  RepeatMethod(std::shared_ptr<const route::Route> route, navigation::RepeatOptions options);
  // On a route a leader is still teaching (fleet/): `route` returns its latest snapshot (null
  // while it has fewer than 2 keyframes: the robot waits); the robot waits at the last keyframe
  // taught so far (RepeatOptions::wait_for_leader is set).
  using RouteSource = std::function<std::shared_ptr<const route::Route>()>;
  RepeatMethod(RouteSource route, navigation::RepeatOptions options, cv::Size image_size);
  const char* name() const override { return "repeat"; }
  bool needs_odometry() const override { return false; }
  cv::Size image_size() const override { return size_; }
  Decision Step(const Observation& observation) override;

 private:
  RouteSource source_;
  navigation::RepeatOptions options_;
  std::shared_ptr<const route::Route> route_;  // the snapshot the session has
  std::optional<navigation::RepeatSession> session_;
  cv::Size size_;
};

// Navigation by the visual potential, to a destination (and home) or along a corridor.
class PotentialMethod : public Method {
 public:
  PotentialMethod(navigation::PlanarFlowCalibration calibration,
                  navigation::PotentialNavOptions options,
                  std::optional<Eigen::Vector2d> destination);
  const char* name() const override { return "navigate"; }
  bool needs_odometry() const override { return true; }
  cv::Size image_size() const override { return size_; }
  Decision Step(const Observation& observation) override;

 private:
  navigation::PotentialNavigator navigator_;
  cv::Size size_;
};

// The appearance route follower (Payá et al.). `route` returns the latest snapshot of the route
// (null while there is none yet): a complete route from disk, or one a leader is still teaching.
class FollowMethod : public Method {
 public:
  using RouteSource = std::function<std::shared_ptr<const route::AppearanceRoute>()>;
  FollowMethod(RouteSource route, navigation::AppearanceFollowerOptions options,
               cv::Size image_size = {});
  const char* name() const override { return "follow"; }
  bool needs_odometry() const override { return true; }
  cv::Size image_size() const override { return size_; }
  Decision Step(const Observation& observation) override;

 private:
  RouteSource route_;
  navigation::AppearanceFollower follower_;
  cv::Size size_;
};

}  // namespace mapless::robot
