// `mapless bench`, the robot-link rows: each adapter's latency, frame received to command
// published (issues 17 and 18: p99 <= 5 ms on loopback). ROS 1 with a ROS master started on
// loopback for the purpose; ROS 2 in a DDS domain of its own on loopback (each middleware's
// registration sets that up: ros1/register.cc, ros2/register.cc).
#include <nlohmann/json.hpp>
#include <string>

#include "mapless/robot/link_bench.h"
#include "mapless/robot/middleware.h"

namespace mapless::bench {

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

void BenchMiddleware(const robot::MiddlewareRegistry& middlewares, const std::string& middleware,
                     nlohmann::json* j) {
  const robot::MiddlewareKind* kind = middlewares.Find(middleware);
  const std::string key = middleware + "_link";
  if (kind == nullptr) {
    (*j)[key] = "not built (scripts/setup.sh --ros, then build again)";
    return;
  }
  try {
    BenchCameras(key + "_", kind->bench, j);
  } catch (const std::exception& e) {
    (*j)[key] = std::string("not measured: ") + e.what();
  }
}

}  // namespace mapless::bench
