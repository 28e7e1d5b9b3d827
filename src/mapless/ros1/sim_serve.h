// `mapless sim serve` over ROS 1: the simulated robot's camera, odometry and /clock as roscpp
// topics, cmd_vel and the method's status back (the loop itself: robot/sim_serve.h).
#pragma once

#include "mapless/robot/robot_file.h"
#include "mapless/robot/sim_serve.h"
#include "mapless/sim/simulation.h"

namespace mapless::ros1 {

// Call StartNode first.
robot::ServeSummary ServeSimulation(sim::Simulation& sim, int robot, const robot::RobotFile& file,
                                    const robot::ServeOptions& options);

}  // namespace mapless::ros1
