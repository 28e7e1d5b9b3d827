#include "mapless/ros1/register.h"

#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <stdexcept>
#include <string>

#include "mapless/ros1/link_bench.h"
#include "mapless/ros1/ros1_link.h"
#include "mapless/ros1/sim_serve.h"

extern char** environ;

namespace mapless::ros1 {

namespace {

// The bench with a ROS master of its own on a loopback port, unless MAPLESS_BENCH_USE_MASTER
// says to use the one ROS_MASTER_URI names.
robot::LinkBenchResult BenchWithOwnMaster(const robot::LinkBenchOptions& options) {
  pid_t master = -1;
  if (std::getenv("MAPLESS_BENCH_USE_MASTER") == nullptr) {
    const int port = 21000 + static_cast<int>(getpid() % 9000);
    const std::string uri = "http://127.0.0.1:" + std::to_string(port);
    setenv("ROS_MASTER_URI", uri.c_str(), 1);
    setenv("ROS_IP", "127.0.0.1", 1);
    const std::string port_text = std::to_string(port);
    char* argv[] = {const_cast<char*>("rosmaster"), const_cast<char*>("--core"),
                    const_cast<char*>("-p"), const_cast<char*>(port_text.c_str()), nullptr};
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, 1, "/dev/null", 1, 0);
    posix_spawn_file_actions_addopen(&actions, 2, "/dev/null", 1, 0);
    const int rc = posix_spawnp(&master, "rosmaster", &actions, nullptr, argv, environ);
    posix_spawn_file_actions_destroy(&actions);
    if (rc != 0) throw std::runtime_error("rosmaster not found (scripts/setup.sh --ros)");
  }
  struct StopMaster {
    pid_t pid;
    ~StopMaster() {
      if (pid > 0) {
        kill(pid, SIGTERM);
        waitpid(pid, nullptr, 0);
      }
    }
  } stop{master};
  return BenchLink(options);
}

}  // namespace

void RegisterMiddleware(robot::MiddlewareRegistry* registry) {
  robot::MiddlewareKind k;
  k.name = "ros1";
  k.open_link = [](const robot::RobotFile& file, cv::Size image_size, const std::string& method,
                   const robot::Logger& warn) -> std::unique_ptr<robot::RobotLink> {
    StartNode(file, file.node_name);
    auto link = std::make_unique<Ros1Link>(file, image_size, method, warn);
    link->Start();
    return link;
  };
  k.serve = [](sim::Simulation& sim, int robot, const robot::RobotFile& file,
               const robot::ServeOptions& options) {
    StartNode(file, "mapless_sim");
    return ServeSimulation(sim, robot, file, options);
  };
  k.bench = BenchWithOwnMaster;
  registry->Add(std::move(k));
}

}  // namespace mapless::ros1
