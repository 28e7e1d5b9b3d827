// The robot link over ROS 1 (roscpp, Debian's Noetic-level packages): subscribes the camera
// (sensor_msgs/Image or CompressedImage), the wheel odometry (nav_msgs/Odometry) and an e-stop
// (std_msgs/Bool); publishes geometry_msgs/Twist on cmd_vel, the per-frame decision as JSON in a
// std_msgs/String and a debug image. Topic names, namespace, limits, camera mount and the safety
// timeouts come from the robot file (robot/robot_file.h).
//
// Safety: Next() reports kNoFrame when no frame arrived for camera_timeout_s (by the ROS clock,
// which is /clock under use_sim_time), kEStop while the e-stop topic says true, and kClosed on
// shutdown; the loop then publishes a zero Twist. Bad input (an unsupported encoding, a frame that
// does not decode) is logged once per kind and never acted on. The destructor of a link that
// commanded the robot publishes a zero Twist before it leaves the ROS graph; a link that only
// listened (teaching) publishes nothing.
#pragma once

#include <functional>
#include <memory>
#include <opencv2/core.hpp>
#include <string>

#include "mapless/robot/inbox.h"
#include "mapless/robot/link.h"
#include "mapless/robot/robot_file.h"

namespace mapless::ros1 {

using Logger = robot::Logger;

// Starts roscpp once per process under the robot file's node name (no SIGINT handler: the app's
// own stops the loop). Sets /use_sim_time on the master when the robot file asks for it. Throws
// std::runtime_error when no master answers within connect_timeout_s.
void StartNode(const robot::RobotFile& robot, const std::string& node_name);

class Ros1Link : public robot::RobotLink {
 public:
  // Subscribes and advertises; nothing is received before Start(). `image_size`: frames are
  // resized to it (0x0: as they come). `method` names the status.
  Ros1Link(const robot::RobotFile& robot, cv::Size image_size, std::string method, Logger warn);
  ~Ros1Link() override;
  // Starts receiving (roscpp's spinner thread): call once, before Next().
  void Start();

  robot::LinkEvent Next() override;
  void Send(const Twist2& command, const robot::Observation& observation,
            const robot::Decision& decision) override;
  void Stop(const std::string& reason) override;
  Timestamp now_ns() const override;

  // Frame received (callback) to command published, nanoseconds (steady clock), for each frame
  // the method decided on.
  const std::vector<std::int64_t>& latencies_ns() const;

  class Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace mapless::ros1
