// A fleet follower's method (`mapless follow --connect`): the method for the route its leader
// announces (the funnel-lane repeat or the eigenspace follower), reading the local copy of the
// route as it grows (fleet::RouteCopy).
#pragma once

#include <memory>

#include "mapless/fleet/route_log.h"
#include "mapless/navigation/appearance.h"
#include "mapless/navigation/repeat.h"
#include "mapless/robot/method.h"
#include "mapless/sim/scenario.h"

namespace mapless::run {

struct FollowerSetup {
  navigation::RepeatOptions repeat;                // funnel routes (the detector is the header's)
  navigation::AppearanceFollowerOptions follower;  // eigenspace routes
};

// `copy` must outlive the method. On the simulator (`scenario` not null) the funnel repeat drives
// at the scenario's repeat speed, as `mapless repeat` does there. The method throws RunFailed when
// the leader completes a route it cannot follow (no route images, fewer than 2 keyframes).
std::unique_ptr<robot::Method> FollowerMethod(const fleet::RouteHeader& header,
                                              const fleet::RouteCopy& copy, FollowerSetup setup,
                                              const sim::Scenario* scenario);

}  // namespace mapless::run
