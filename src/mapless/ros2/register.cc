#include "mapless/ros2/register.h"

#include <unistd.h>

#include <cstdlib>
#include <string>

#include "mapless/ros2/link_bench.h"
#include "mapless/ros2/ros2_link.h"
#include "mapless/ros2/sim_serve.h"

namespace mapless::ros2 {

namespace {

// The bench in a DDS domain of its own on loopback, unless ROS_DOMAIN_ID chooses one.
robot::LinkBenchResult BenchInOwnDomain(const robot::LinkBenchOptions& options) {
  if (std::getenv("ROS_DOMAIN_ID") == nullptr) {
    const std::string domain = std::to_string(201 + static_cast<int>(getpid() % 30));
    setenv("ROS_DOMAIN_ID", domain.c_str(), 1);
    setenv("ROS_LOCALHOST_ONLY", "1", 1);
  }
  return BenchLink(options);
}

}  // namespace

void RegisterMiddleware(robot::MiddlewareRegistry* registry) {
  robot::MiddlewareKind k;
  k.name = "ros2";
  k.open_link = [](const robot::RobotFile& file, cv::Size image_size, const std::string& method,
                   const robot::Logger& warn) -> std::unique_ptr<robot::RobotLink> {
    auto link = std::make_unique<Ros2Link>(file, image_size, method, warn);
    link->Start();
    return link;
  };
  k.serve = ServeSimulation;
  k.bench = BenchInOwnDomain;
  registry->Add(std::move(k));
}

}  // namespace mapless::ros2
