// The three methods of mapless behind the common face of method.h.
#pragma once

#include <Eigen/Core>
#include <functional>
#include <memory>
#include <optional>

#include "mapless/navigation/appearance.h"
#include "mapless/navigation/potential.h"
#include "mapless/navigation/repeat.h"
#include "mapless/robot/method.h"
#include "mapless/route/appearance_route.h"
#include "mapless/route/route.h"

namespace mapless::robot {

// Each method's detail of a decision (method.h): its navigation step, its status fields and its
// debug picture. `Decision::DetailAs<RepeatDetail>()->step` gives the step back.
struct RepeatDetail : DecisionDetail {
  explicit RepeatDetail(navigation::RepeatStep s) : step(std::move(s)) {}
  void Fields(nlohmann::json* j) const override;
  void Draw(cv::Mat* picture, double scale, std::vector<std::string>* lines) const override;
  navigation::RepeatStep step;
};
struct PotentialDetail : DecisionDetail {
  explicit PotentialDetail(navigation::PotentialStep s) : step(std::move(s)) {}
  void Fields(nlohmann::json* j) const override;
  void Draw(cv::Mat* picture, double scale, std::vector<std::string>* lines) const override;
  navigation::PotentialStep step;
};
struct FollowerDetail : DecisionDetail {
  explicit FollowerDetail(navigation::FollowerStep s) : step(std::move(s)) {}
  void Fields(nlohmann::json* j) const override;
  void Draw(cv::Mat* picture, double scale, std::vector<std::string>* lines) const override;
  navigation::FollowerStep step;
};

// Visual teach & repeat with funnel lanes (Algorithm 1 of Kassir et al.).
class RepeatMethod : public Method {
 public:
  RepeatMethod(std::shared_ptr<const route::Route> route, navigation::RepeatOptions options);
  // On a route a leader is still teaching (fleet/): `route` returns its latest snapshot (null
  // while it has fewer than 2 keyframes: the robot waits); the robot waits at the last keyframe
  // taught so far (RepeatOptions::wait_for_leader is set).
  using RouteSource = std::function<std::shared_ptr<const route::Route>()>;
  RepeatMethod(RouteSource route, navigation::RepeatOptions options, cv::Size image_size);
  // The same, with the route read in pieces: `updates` appends to the route what is new since the
  // last call and says whether anything changed (fleet::RouteCopy::UpdateFunnel), so the work per
  // frame is the new keyframes', whatever the route's length.
  using RouteUpdates = std::function<bool(route::Route* route)>;
  RepeatMethod(RouteUpdates updates, navigation::RepeatOptions options, cv::Size image_size);
  const char* name() const override { return "repeat"; }
  bool needs_odometry() const override { return false; }
  cv::Size image_size() const override { return size_; }
  Decision Step(const Observation& observation) override;
  // The session once the route has 2 keyframes (null before): what it learned (experiences).
  navigation::RepeatSession* session() { return session_ ? &*session_ : nullptr; }

 private:
  RouteSource source_;
  RouteUpdates updates_;
  std::shared_ptr<route::Route> live_;  // the route read in pieces (updates_), this thread's own
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
  // What the follower learned (AppearanceFollowerOptions::learn) and used, for the route.
  const navigation::AppearanceFollower& follower() const { return follower_; }

 private:
  RouteSource route_;
  navigation::AppearanceFollower follower_;
  cv::Size size_;
};

}  // namespace mapless::robot
