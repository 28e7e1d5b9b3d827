// The ROS 2 adapter's own latency (issue 18): frames written on loopback DDS (a domain of its
// own, ROS_DOMAIN_ID) into a Ros2Link whose method answers at once (robot/link_bench.h).
#pragma once

#include "mapless/robot/link_bench.h"

namespace mapless::ros2 {

robot::LinkBenchResult BenchLink(const robot::LinkBenchOptions& options);

}  // namespace mapless::ros2
