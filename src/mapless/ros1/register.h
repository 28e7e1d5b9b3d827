// ROS 1 as a middleware of the robot link (robot/middleware.h): the link, `sim serve` and the
// latency bench, registered under the name `ros1`.
#pragma once

#include "mapless/robot/middleware.h"

namespace mapless::ros1 {

void RegisterMiddleware(robot::MiddlewareRegistry* registry);

}  // namespace mapless::ros1
