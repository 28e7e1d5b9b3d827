// The robot link over ROS 2, spoken as plain DDS (Cyclone DDS; dds.h says how it follows the ROS
// 2 conventions): subscribes the camera (sensor_msgs/Image or CompressedImage), the wheel odometry
// (nav_msgs/Odometry), an e-stop (std_msgs/Bool) and, under use_sim_time, /clock; publishes
// geometry_msgs/Twist on cmd_vel, the per-frame decision as JSON in a std_msgs/String and a bgr8
// debug image (only while someone subscribes). Topic names, namespace, limits, camera mount and the
// safety timeouts come from the robot file, as for ROS 1.
//
// Safety is the ROS 1 adapter's (the watchdog is robot/inbox.h, shared): kNoFrame when no frame
// came for camera_timeout_s by the ROS clock, kEStop while the e-stop says true, bad input logged
// once per kind and never acted on, and a zero Twist (waited for until acknowledged, at most
// 0.5 s) when a link that commanded the robot is destroyed.
#pragma once

#include <cstdint>
#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "mapless/robot/inbox.h"
#include "mapless/robot/link.h"
#include "mapless/robot/robot_file.h"

namespace mapless::ros2 {

class Ros2Link : public robot::RobotLink {
 public:
  // Joins the ROS domain (dds.h) and creates the readers and writers; nothing is handed to the
  // loop before Start(). Throws std::runtime_error when DDS cannot start, InputError for a bad
  // ROS_DOMAIN_ID.
  Ros2Link(const robot::RobotFile& robot, cv::Size image_size, std::string method,
           robot::Logger warn);
  ~Ros2Link() override;
  void Start();

  robot::LinkEvent Next() override;
  void Send(const Twist2& command, const robot::Observation& observation,
            const robot::Decision& decision) override;
  void Stop(const std::string& reason) override;
  Timestamp now_ns() const override;

  // Frame received (the DDS listener) to command written, nanoseconds, per decided frame.
  const std::vector<std::int64_t>& latencies_ns() const;

  class Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace mapless::ros2
