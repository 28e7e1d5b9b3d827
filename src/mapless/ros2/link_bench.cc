#include "mapless/ros2/link_bench.h"

#include <atomic>
#include <chrono>
#include <cmath>
#include <map>
#include <mutex>
#include <opencv2/imgproc.hpp>
#include <thread>

#include "mapless/robot/loop.h"
#include "mapless/robot/robot_file.h"
#include "mapless/ros2/dds.h"
#include "mapless/ros2/messages.h"
#include "mapless/ros2/ros2_link.h"

namespace mapless::ros2 {

namespace {

using Clock = std::chrono::steady_clock;

struct Listener {
  std::mutex mutex;
  std::map<std::int64_t, Clock::time_point> sent;  // sub-second stamp -> written at
  std::vector<double> end_to_end;
};

void OnTwist(dds_entity_t reader, void* arg) {
  auto* l = static_cast<Listener*>(arg);
  const auto now = Clock::now();
  TakeAll<geometry_msgs_msg_dds__Twist_>(reader, [&](const geometry_msgs_msg_dds__Twist_& t) {
    const auto key = static_cast<std::int64_t>(std::llround(t.angular.z * 1e9));
    std::lock_guard<std::mutex> lock(l->mutex);
    if (auto it = l->sent.find(key); it != l->sent.end()) {
      l->end_to_end.push_back(std::chrono::duration<double, std::milli>(now - it->second).count());
      l->sent.erase(it);
    }
  });
}

// The camera and the listener, on a thread of their own. They share the link's participant, so
// Cyclone delivers frames and commands locally (serialised, but not through the loopback sockets):
// the end-to-end figure is the adapter's plus the middleware's own path in one process. (A
// camera forked into a process of its own never matched the link here; not investigated further.
// The closed-loop tests cross the loopback sockets.) Returns the end-to-end latencies, ms.
std::vector<double> Camera(const robot::RobotFile& file, const robot::LinkBenchOptions& options) {
  const dds_entity_t camera =
      MakeWriter(&sensor_msgs_msg_dds__Image__desc, file.Resolve(file.topics.image),
                 "sensor_msgs/msg/Image", Qos::kSensorData);
  Listener listener;
  dds_listener_t* l = dds_create_listener(&listener);
  dds_lset_data_available(l, OnTwist);
  const dds_entity_t commands =
      MakeReader(&geometry_msgs_msg_dds__Twist__desc, file.Resolve(file.topics.cmd_vel),
                 "geometry_msgs/msg/Twist", Qos::kDefault, l);
  const auto deadline = Clock::now() + std::chrono::seconds(20);
  while ((MatchedReaders(camera) == 0 || MatchedWriters(commands) == 0) && Clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  cv::Mat grey(options.camera, CV_8UC1);
  cv::randu(grey, 0, 255);
  cv::Mat image = grey;
  if (options.encoding == "rgb8") cv::cvtColor(grey, image, cv::COLOR_GRAY2RGB);
  robot::CameraMessage msg;
  msg.encoding = options.encoding;
  msg.width = static_cast<std::uint32_t>(image.cols);
  msg.height = static_cast<std::uint32_t>(image.rows);
  msg.step = static_cast<std::uint32_t>(image.cols * image.channels());
  msg.data.assign(image.data, image.data + image.total() * image.elemSize());
  const auto period = std::chrono::duration<double>(1.0 / options.rate_hz);
  auto next = Clock::now();
  for (int i = 0; i < options.frames; ++i) {
    const Timestamp stamp = std::chrono::duration_cast<std::chrono::nanoseconds>(
                                std::chrono::system_clock::now().time_since_epoch())
                                .count();
    {
      std::lock_guard<std::mutex> lock(listener.mutex);
      listener.sent[stamp % 1000000000] = Clock::now();
    }
    WriteImage(camera, stamp, "camera", msg);
    next += std::chrono::duration_cast<Clock::duration>(period);
    std::this_thread::sleep_until(next);
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  Delete(commands);
  Delete(camera);
  dds_delete_listener(l);
  std::lock_guard<std::mutex> lock(listener.mutex);
  return listener.end_to_end;
}

}  // namespace

robot::LinkBenchResult BenchLink(const robot::LinkBenchOptions& options) {
  const robot::RobotFile file = robot::ParseRobotFile(
      "name: bench\nmiddleware: ros2\nnamespace: mapless_bench\n"
      "topics: {odometry: '', estop: '', debug_image: ''}\n"
      "safety: {give_up_without_frames_s: 0}\n",
      "bench robot file");
  robot::EchoMethod method(options.method);
  robot::LinkBenchResult result;
  std::vector<double> end_to_end;
  {
    Ros2Link link(file, options.method, "bench", {});
    link.Start();
    std::atomic<bool> done{false};
    std::thread loop([&] {
      robot::LoopOptions loop_options;
      robot::RunLoop(method, link, loop_options, {}, [&] { return done.load(); });
    });
    end_to_end = Camera(file, options);
    done = true;
    loop.join();
    std::vector<double> adapter;
    for (const std::int64_t ns : link.latencies_ns())
      adapter.push_back(static_cast<double>(ns) * 1e-6);
    result.frames = static_cast<int>(adapter.size());
    result.adapter_median_ms = robot::Percentile(adapter, 0.5);
    result.adapter_p99_ms = robot::Percentile(adapter, 0.99);
  }
  result.end_to_end_median_ms = robot::Percentile(end_to_end, 0.5);
  result.end_to_end_p99_ms = robot::Percentile(end_to_end, 0.99);
  return result;
}

}  // namespace mapless::ros2
