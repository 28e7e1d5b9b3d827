// ROS 2 (plain DDS) as a middleware of the robot link (robot/middleware.h): the link, `sim serve`
// and the latency bench, registered under the name `ros2`.
#pragma once

#include "mapless/robot/middleware.h"

namespace mapless::ros2 {

void RegisterMiddleware(robot::MiddlewareRegistry* registry);

}  // namespace mapless::ros2
