// The middlewares a robot can be reached over (ROS 1, ROS 2, ...), each supplied by the module
// that implements it (src/mapless/ros1, src/mapless/ros2) through one registration function. The
// command line looks a robot file's `middleware:` up here instead of naming each middleware, so a
// build without one simply has no entry for it, and a robot file that asks for it gets one clear
// line. Which modules register is decided by the build (cmake/MaplessHelpers.cmake,
// `mapless_register_middleware`), never by `#ifdef` in the code that uses them.
#pragma once

#include <functional>
#include <memory>
#include <opencv2/core/types.hpp>
#include <string>
#include <vector>

#include "mapless/robot/inbox.h"
#include "mapless/robot/link.h"
#include "mapless/robot/link_bench.h"
#include "mapless/robot/robot_file.h"
#include "mapless/robot/sim_serve.h"
#include "mapless/sim/simulation.h"

namespace mapless::robot {

struct MiddlewareKind {
  std::string name;  // as a robot file names it: `middleware: ros1`
  // The robot link for a method that wants frames of `image_size` (0x0: as they come); `method`
  // names the method in the status the link publishes; `warn` hears about bad input. Started, ready
  // for RobotLink::Next.
  std::function<std::unique_ptr<RobotLink>(const RobotFile& file, cv::Size image_size,
                                           const std::string& method, const Logger& warn)>
      open_link;
  // `mapless sim serve`: robot `robot` of the simulation served over this middleware until the
  // serve ends (robot/sim_serve.h).
  std::function<ServeSummary(sim::Simulation& sim, int robot, const RobotFile& file,
                             const ServeOptions& options)>
      serve;
  // `mapless bench`: the adapter's own latency, with what the middleware needs (a master, a
  // domain) set up on loopback by the function itself. Throws when it cannot be measured.
  std::function<LinkBenchResult(const LinkBenchOptions& options)> bench;
};

class MiddlewareRegistry {
 public:
  // Throws std::logic_error when a kind of that name is registered already or a function is
  // missing (a programming error).
  void Add(MiddlewareKind kind);
  // nullptr when this build has no such middleware.
  const MiddlewareKind* Find(const std::string& name) const;
  // The file's middleware; throws InputError naming the file and what this build has when it
  // has not this one.
  const MiddlewareKind& For(const RobotFile& file) const;
  // The names registered, in the order of registration.
  std::vector<std::string> names() const;

 private:
  std::vector<MiddlewareKind> kinds_;
};

}  // namespace mapless::robot
