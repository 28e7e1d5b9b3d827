#include "mapless/ros1/link_bench.h"

#include <geometry_msgs/Twist.h>
#include <ros/ros.h>
#include <sensor_msgs/Image.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <map>
#include <mutex>
#include <opencv2/imgproc.hpp>
#include <thread>

#include "mapless/robot/loop.h"
#include "mapless/robot/robot_file.h"
#include "mapless/ros1/ros1_link.h"

namespace mapless::ros1 {

namespace {

using Clock = std::chrono::steady_clock;

}  // namespace

LinkBenchResult BenchLink(const LinkBenchOptions& options) {
  robot::RobotFile file = robot::ParseRobotFile(
      "name: bench\nnamespace: mapless_bench\nnode_name: mapless_bench\n"
      "topics: {odometry: '', estop: '', debug_image: ''}\n"
      "safety: {give_up_without_frames_s: 0}\n",
      "bench robot file");
  StartNode(file, file.node_name);
  ros::NodeHandle nh;
  ros::Publisher camera = nh.advertise<sensor_msgs::Image>(file.Resolve(file.topics.image), 10);
  std::mutex mutex;
  std::map<std::int64_t, Clock::time_point> sent;  // stamp -> publish time
  std::vector<double> end_to_end;
  ros::Subscriber listener = nh.subscribe<geometry_msgs::Twist>(
      file.Resolve(file.topics.cmd_vel), 100,
      [&](const geometry_msgs::TwistConstPtr& msg) {
        const auto now = Clock::now();
        const auto key = static_cast<std::int64_t>(std::llround(msg->angular.z * 1e9));
        std::lock_guard<std::mutex> lock(mutex);
        if (auto it = sent.find(key); it != sent.end()) {
          end_to_end.push_back(std::chrono::duration<double, std::milli>(now - it->second).count());
          sent.erase(it);
        }
      },
      ros::VoidConstPtr(), ros::TransportHints().tcpNoDelay());
  ros::AsyncSpinner spinner(1);
  spinner.start();

  robot::EchoMethod method(options.method);
  LinkBenchResult result;
  {
    Ros1Link link(file, options.method, "bench", {});
    link.Start();
    // Wait for both connections.
    const auto deadline = Clock::now() + std::chrono::seconds(10);
    while ((camera.getNumSubscribers() == 0 || listener.getNumPublishers() == 0) &&
           Clock::now() < deadline)
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    std::atomic<bool> done{false};
    std::thread loop([&] {
      robot::LoopOptions loop_options;
      robot::RunLoop(method, link, loop_options, {}, [&] { return done.load(); });
    });
    cv::Mat grey(options.camera, CV_8UC1);
    cv::randu(grey, 0, 255);
    cv::Mat image = grey;
    if (options.encoding == "rgb8") cv::cvtColor(grey, image, cv::COLOR_GRAY2RGB);
    const auto period = std::chrono::duration<double>(1.0 / options.rate_hz);
    auto next = Clock::now();
    for (int i = 0; i < options.frames; ++i) {
      sensor_msgs::Image msg;
      msg.header.stamp = ros::Time::now();
      // Stamps unique in their sub-second part, to pair the command with its frame.
      msg.width = static_cast<std::uint32_t>(image.cols);
      msg.height = static_cast<std::uint32_t>(image.rows);
      msg.encoding = options.encoding;
      msg.step = static_cast<std::uint32_t>(image.cols * image.channels());
      msg.data.assign(image.data, image.data + image.total() * image.elemSize());
      {
        std::lock_guard<std::mutex> lock(mutex);
        sent[static_cast<std::int64_t>(msg.header.stamp.toNSec() % 1000000000ULL)] = Clock::now();
      }
      camera.publish(msg);
      next += std::chrono::duration_cast<Clock::duration>(period);
      std::this_thread::sleep_until(next);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    done = true;
    loop.join();
    std::vector<double> adapter;
    for (const std::int64_t ns : link.latencies_ns()) adapter.push_back(ns * 1e-6);
    result.frames = static_cast<int>(adapter.size());
    result.adapter_median_ms = robot::Percentile(adapter, 0.5);
    result.adapter_p99_ms = robot::Percentile(adapter, 0.99);
  }
  std::lock_guard<std::mutex> lock(mutex);
  result.end_to_end_median_ms = robot::Percentile(end_to_end, 0.5);
  result.end_to_end_p99_ms = robot::Percentile(end_to_end, 0.99);
  spinner.stop();
  return result;
}

}  // namespace mapless::ros1
