// The middlewares this build of `mapless` can reach a robot over (ROS 1, ROS 2, ...), from the
// modules that registered with mapless_register_middleware (cmake/MaplessHelpers.cmake).
#pragma once

#include "mapless/robot/middleware.h"

namespace mapless::app {

const robot::MiddlewareRegistry& BuiltinMiddlewares();

}  // namespace mapless::app
