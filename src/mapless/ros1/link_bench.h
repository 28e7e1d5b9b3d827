// The ROS 1 adapter's own latency (issue 17): frames published on loopback into a Ros1Link whose
// method answers at once, so what is measured is what the adapter adds: receiving and converting
// the image, handing it to the loop, publishing the Twist and the status. Needs a ROS master
// (ROS_MASTER_URI); `mapless bench` starts one on loopback when rosmaster is installed.
#pragma once

#include "mapless/robot/link_bench.h"

namespace mapless::ros1 {

using robot::LinkBenchOptions;
using robot::LinkBenchResult;

// Needs a ROS master (ROS_MASTER_URI); `mapless bench --ros1` starts one on loopback.
LinkBenchResult BenchLink(const LinkBenchOptions& options);

}  // namespace mapless::ros1
