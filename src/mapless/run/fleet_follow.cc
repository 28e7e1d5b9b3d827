#include "mapless/run/fleet_follow.h"

#include <stdexcept>
#include <string>

#include "mapless/core/check.h"
#include "mapless/eval/teach_repeat.h"
#include "mapless/features/features.h"
#include "mapless/robot/methods.h"

namespace mapless::run {

std::unique_ptr<robot::Method> FollowerMethod(const fleet::RouteHeader& header,
                                              const fleet::RouteCopy& copy, FollowerSetup setup,
                                              const sim::Scenario* scenario) {
  const cv::Size size(header.image_width, header.image_height);
  if (header.kind == fleet::RouteKind::kEigenspace) {
    return std::make_unique<robot::FollowMethod>(
        [&copy] {
          auto route = copy.AppearanceRoute();
          if (!route && copy.complete())  // waiting for more cannot help
            throw std::runtime_error("follow: the leader completed its route without route images");
          return route;
        },
        setup.follower, size);
  }
  navigation::RepeatOptions& repeat = setup.repeat;
  repeat.features.type = features::ParseDetectorType(header.detector);
  if (scenario != nullptr) {
    const double speed =
        eval::RepeatSpeedFor(*scenario, eval::RepeatRunOptions{}.max_repeat_speed_mps);
    repeat.sloped.max_speed_mps = speed;
    repeat.standard.forward_speed_mps = speed;
  }
  return std::make_unique<robot::RepeatMethod>(
      robot::RepeatMethod::RouteUpdates([&copy](route::Route* route) {
        const bool changed = copy.UpdateFunnel(route);
        if (route->complete && route->keyframes.size() < 2)
          throw std::runtime_error("follow: the leader completed its route with " +
                                   std::to_string(route->keyframes.size()) +
                                   " keyframes; a route to follow needs at least 2");
        return changed;
      }),
      repeat, size);
}

}  // namespace mapless::run
