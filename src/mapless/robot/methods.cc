#include "mapless/robot/methods.h"

#include <utility>

#include "mapless/core/check.h"

namespace mapless::robot {

const char* MethodStateName(MethodState state) {
  switch (state) {
    case MethodState::kDriving:
      return "driving";
    case MethodState::kStopped:
      return "stopped";
    case MethodState::kFinished:
      return "finished";
    case MethodState::kFailed:
      return "failed";
  }
  return "?";
}

namespace {

Decision Make(MethodState state, const Twist2& command, std::string status, std::string reason) {
  Decision d;
  d.state = state;
  d.command = state == MethodState::kDriving ? command : Twist2{};
  d.status = std::move(status);
  d.reason = std::move(reason);
  return d;
}

// A method that needs odometry does not drive on a frame without it.
Decision NoOdometry(const char* method) {
  return Make(MethodState::kStopped, {}, "stopped",
              std::string(method) + " needs wheel odometry and this frame has none");
}

}  // namespace

// ---- repeat ----------------------------------------------------------------------------------

RepeatMethod::RepeatMethod(std::shared_ptr<const route::Route> route,
                           navigation::RepeatOptions options)
    : options_(options), route_(route), size_(route->image_width, route->image_height) {
  session_.emplace(route, options);
}

RepeatMethod::RepeatMethod(RouteSource route, navigation::RepeatOptions options,
                           cv::Size image_size)
    : source_(std::move(route)), options_(options), size_(image_size) {
  options_.wait_for_leader = true;
}

RepeatMethod::RepeatMethod(RouteUpdates updates, navigation::RepeatOptions options,
                           cv::Size image_size)
    : updates_(std::move(updates)),
      live_(std::make_shared<route::Route>()),
      options_(options),
      size_(image_size) {
  options_.wait_for_leader = true;
}

Decision RepeatMethod::Step(const Observation& observation) {
  if (updates_) {
    if (updates_(live_.get())) {
      if (session_) {
        session_->Extend(live_);  // the same route, longer or complete now
      } else if (live_->keyframes.size() >= 2) {
        session_.emplace(live_, options_);
        route_ = live_;
      }
    }
    if (!session_)
      return Make(MethodState::kStopped, Twist2{}, "waiting",
                  "waiting for the leader: the route has fewer than 2 keyframes yet");
  }
  if (source_) {
    std::shared_ptr<const route::Route> latest = source_();
    if (latest && latest != route_) {
      if (session_) {
        session_->Extend(latest);
      } else {
        session_.emplace(latest, options_);
      }
      route_ = std::move(latest);
    }
    if (!session_)
      return Make(MethodState::kStopped, Twist2{}, "waiting",
                  "waiting for the leader: the route has fewer than 2 keyframes yet");
  }
  navigation::RepeatStep step =
      session_->Update(observation.image, observation.t_ns, observation.odometry);
  MethodState state = MethodState::kDriving;
  switch (step.status) {
    case navigation::RepeatStatus::kDriving:
      state = MethodState::kDriving;
      break;
    case navigation::RepeatStatus::kWaiting:
    case navigation::RepeatStatus::kBlocked:
      state = MethodState::kStopped;
      break;
    case navigation::RepeatStatus::kCompleted:
      state = MethodState::kFinished;
      break;
    case navigation::RepeatStatus::kAborted:
      state = MethodState::kFailed;
      break;
  }
  Decision d = Make(state, step.command, navigation::RepeatStatusName(step.status), step.reason);
  d.blocked = step.status == navigation::RepeatStatus::kBlocked;
  d.detail = std::make_shared<RepeatDetail>(std::move(step));
  return d;
}

// ---- navigate --------------------------------------------------------------------------------

PotentialMethod::PotentialMethod(navigation::PlanarFlowCalibration calibration,
                                 navigation::PotentialNavOptions options,
                                 std::optional<Eigen::Vector2d> destination)
    : navigator_(calibration, options), size_(calibration.width, calibration.height) {
  if (destination) navigator_.SetDestination(*destination);
}

Decision PotentialMethod::Step(const Observation& observation) {
  if (!observation.odometry) return NoOdometry(name());
  navigation::PotentialStep step = navigator_.Update(observation.image, *observation.odometry);
  MethodState state = MethodState::kStopped;
  switch (step.status) {
    case navigation::PotentialStatus::kDriving:
    case navigation::PotentialStatus::kLooking:
    case navigation::PotentialStatus::kSearching:
    case navigation::PotentialStatus::kTurningAround:
      // Searching and turning round move the robot too (in place, or one creeping frame).
      state = MethodState::kDriving;
      break;
    case navigation::PotentialStatus::kArrived:
      state = MethodState::kFinished;
      break;
    case navigation::PotentialStatus::kAborted:
      state = MethodState::kFailed;
      break;
    case navigation::PotentialStatus::kCameraFault:
      state = MethodState::kStopped;
      break;
  }
  Decision d = Make(state, step.command, navigation::PotentialStatusName(step.status), step.reason);
  d.detail = std::make_shared<PotentialDetail>(std::move(step));
  return d;
}

// ---- follow ----------------------------------------------------------------------------------

FollowMethod::FollowMethod(RouteSource route, navigation::AppearanceFollowerOptions options,
                           cv::Size image_size)
    : route_(std::move(route)), follower_(options), size_(image_size) {
  MAPLESS_CHECK(route_, "FollowMethod: no route source");
}

Decision FollowMethod::Step(const Observation& observation) {
  if (!observation.odometry) return NoOdometry(name());
  const std::shared_ptr<const route::AppearanceRoute> route = route_();
  if (!route || route->size() == 0) {
    return Make(MethodState::kStopped, {}, "waiting", "no route image yet: waiting for the leader");
  }
  navigation::FollowerStep step =
      follower_.Update(observation.image, *observation.odometry, *route, observation.t_ns);
  MethodState state = MethodState::kDriving;
  switch (step.state) {
    case navigation::FollowerState::kInitializing:
    case navigation::FollowerState::kFollowing:
      state = MethodState::kDriving;
      break;
    case navigation::FollowerState::kStopped:
    case navigation::FollowerState::kWaitingForLeader:
      state = MethodState::kStopped;
      break;
    case navigation::FollowerState::kArrived:
      state = MethodState::kFinished;
      break;
  }
  Decision d = Make(state, step.command, navigation::FollowerStateName(step.state), step.reason);
  d.blocked = step.obstacle.blocked && state == MethodState::kStopped;
  d.detail = std::make_shared<FollowerDetail>(std::move(step));
  return d;
}

}  // namespace mapless::robot
