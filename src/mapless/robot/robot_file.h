// The robot file: one YAML file with everything mapless needs to know about a robot — which
// middleware, the topic names and namespace, the speed limits, the camera mounting and the safety
// timeouts. Conventional ROS defaults (REP-103 units, `camera/image_raw`, `odom`, `cmd_vel`) so
// that a robot that follows the conventions needs a file of one line. Commented example:
// config/robots/turtlebot.yaml. Unknown fields are errors naming the file, line and field.
#pragma once

#include <string>

#include "mapless/navigation/obstacle_watch.h"
#include "mapless/robot/loop.h"

namespace mapless::robot {

// The middleware names a robot file may use; which of them this build can reach is
// robot/middleware.h's registry.
inline constexpr const char* kMiddlewareNames[] = {"ros1", "ros2"};

// How the camera is mounted: the image is turned upright before the method sees it.
enum class CameraMount { kUpright, kRotated180, kMirrored, kFlippedVertically };
const char* CameraMountName(CameraMount m);

struct RobotTopics {
  std::string image = "camera/image_raw";  // sensor_msgs/Image (mono8, rgb8, bgr8, ...)
  // sensor_msgs/CompressedImage (JPEG or PNG); used instead of `image` when set.
  std::string compressed_image;
  std::string odometry = "odom";                    // nav_msgs/Odometry; "" for a robot without
  std::string cmd_vel = "cmd_vel";                  // geometry_msgs/Twist
  std::string status = "mapless/status";            // std_msgs/String, one JSON object per frame
  std::string debug_image = "mapless/debug_image";  // sensor_msgs/Image (bgr8); "" for none
  std::string estop = "mapless/estop";              // std_msgs/Bool: true stops the robot
};

struct RobotFile {
  std::string source;                 // the file it came from (for messages)
  std::string middleware = "ros1";    // one of kMiddlewareNames
  std::string name = "robot";         // a name for logs
  std::string ns;                     // namespace prefixed to relative topics ("/robot1")
  std::string node_name = "mapless";  // the ROS node name
  RobotTopics topics;
  double max_speed_mps = 0.3;        // REP-103: m/s
  double max_turn_rate_radps = 1.0;  // REP-103: rad/s
  CameraMount mount = CameraMount::kUpright;
  // Safety: zero velocity when no frame arrived for camera_timeout_s; a frame older than
  // max_frame_age_s (its stamp against the clock) is never acted on.
  double camera_timeout_s = 0.2;
  double max_frame_age_s = 0.5;
  // No frame for this long: the run ends (exit 1). 0: the robot waits stopped for ever.
  double give_up_without_frames_s = 30.0;
  // Stopped for an obstacle this long without a break: the run ends with exit 1 and the reason
  // (safety.max_blocked_s; 0: wait for ever).
  double max_blocked_s = 60.0;
  // The obstacle watch of `repeat` (section `obstacles`): on_obstacle stop (default) or off, and
  // the image region the robot drives through next, for this robot's camera.
  navigation::ObstacleWatchOptions obstacle;
  bool obstacle_baseline_given = false;  // obstacles.baseline_m is in the file (else each method's)
  bool obstacle_max_unchecked_given = false;  // obstacles.max_unchecked_m likewise
  bool use_sim_time = false;                  // ROS `use_sim_time`: the clock comes from /clock
  double connect_timeout_s = 10.0;            // waiting for the master / the first subscriber
  // Threads the method may use on the robot's computer: 2 runs `repeat`'s obstacle watch beside
  // the frame's feature detection (RepeatOptions::threads), `teach`'s tracking in two halves and
  // `navigate`'s optical flow on two (FlowOptions::threads); same decisions, shorter latency.
  int threads = 2;
  // The full name of a topic: absolute topics stay, relative ones get the namespace.
  std::string Resolve(const std::string& topic) const;
  LoopOptions Loop() const;
  void Validate() const;
};

RobotFile LoadRobotFile(const std::string& path);
// The same from text; `name` stands for the file in errors.
RobotFile ParseRobotFile(const std::string& text, const std::string& name);

}  // namespace mapless::robot
