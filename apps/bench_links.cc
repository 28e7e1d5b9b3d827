// `mapless bench`, the robot-link rows: each adapter's latency, frame received to command
// published (issues 17 and 18: p99 <= 5 ms on loopback). ROS 1 with a ROS master started on
// loopback for the purpose; ROS 2 in a DDS domain of its own on loopback.
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>

#ifdef MAPLESS_HAVE_ROS1
#include "mapless/ros1/link_bench.h"
#endif
#ifdef MAPLESS_HAVE_ROS2
#include "mapless/ros2/link_bench.h"
#endif
#include "mapless/robot/link_bench.h"

extern char** environ;

namespace mapless::app {

namespace {

// Both cameras of the bench: the methods' own 320x240 grey, and a common colour camera.
template <typename Bench>
void BenchCameras(const std::string& prefix, Bench bench, nlohmann::json* j) {
  for (const auto& [name, camera, encoding] :
       {std::tuple<const char*, cv::Size, const char*>{"320x240_mono8", {320, 240}, "mono8"},
        {"640x480_rgb8", {640, 480}, "rgb8"}}) {
    robot::LinkBenchOptions o;
    o.camera = camera;
    o.encoding = encoding;
    const robot::LinkBenchResult r = bench(o);
    const std::string key = prefix + name;
    (*j)[key + "_frames"] = r.frames;
    (*j)[key + "_adapter_median_ms"] = r.adapter_median_ms;
    (*j)[key + "_adapter_p99_ms"] = r.adapter_p99_ms;
    (*j)[key + "_end_to_end_median_ms"] = r.end_to_end_median_ms;
    (*j)[key + "_end_to_end_p99_ms"] = r.end_to_end_p99_ms;
  }
}

}  // namespace

void BenchRos1(nlohmann::json* j) {
#ifndef MAPLESS_HAVE_ROS1
  (*j)["ros1_link"] = "not built (scripts/setup.sh --ros, then build again)";
#else
  // A master of our own on a loopback port, unless the caller points us at one.
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
    if (rc != 0) {
      (*j)["ros1_link"] = "not measured: rosmaster not found (scripts/setup.sh --ros)";
      return;
    }
  }
  try {
    BenchCameras("ros1_link_", ros1::BenchLink, j);
  } catch (const std::exception& e) {
    (*j)["ros1_link"] = std::string("not measured: ") + e.what();
  }
  if (master > 0) {
    kill(master, SIGTERM);
    waitpid(master, nullptr, 0);
  }
#endif
}

void BenchRos2(nlohmann::json* j) {
#ifndef MAPLESS_HAVE_ROS2
  (*j)["ros2_link"] = "not built (scripts/setup.sh --ros, then build again)";
#else
  // A domain of our own on loopback, unless the caller chose one.
  if (std::getenv("ROS_DOMAIN_ID") == nullptr) {
    const std::string domain = std::to_string(201 + static_cast<int>(getpid() % 30));
    setenv("ROS_DOMAIN_ID", domain.c_str(), 1);
    setenv("ROS_LOCALHOST_ONLY", "1", 1);
  }
  try {
    BenchCameras("ros2_link_", ros2::BenchLink, j);
  } catch (const std::exception& e) {
    (*j)["ros2_link"] = std::string("not measured: ") + e.what();
  }
#endif
}

}  // namespace mapless::app
