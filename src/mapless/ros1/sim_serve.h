// `mapless sim serve`: the simulator as a ROS 1 robot. Publishes the simulated camera
// (sensor_msgs/Image, mono8), the wheel odometry (nav_msgs/Odometry, frame `odom`, child
// `base_link`) and, under use_sim_time, /clock; obeys geometry_msgs/Twist on cmd_vel.
//
// Lockstep (use_sim_time): it waits until a method has connected, then publishes one frame, waits
// for the one command the method answers it with, advances one camera period and publishes the
// next: runs are deterministic and as fast as the method. Real time (otherwise): it publishes at
// the camera rate and, like a robot base, stops the robot when no command came for 0.5 s.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "mapless/robot/robot_file.h"
#include "mapless/sim/simulation.h"

namespace mapless::ros1 {

struct ServeOptions {
  double period_s = 0.1;
  double timeout_s = 1e9;          // simulated time: the serve ends
  double command_timeout_s = 0.5;  // real time: no command this long stops the robot
  // How the camera is published, to try a method against other cameras: "mono8", "rgb8", "bgr8"
  // (sensor_msgs/Image on topics.image), "jpeg" or "png" (CompressedImage on
  // topics.compressed_image); any other name is published as a raw Image with that encoding and
  // two bytes a pixel (to test how a method meets an encoding it does not know).
  std::string encoding = "mono8";
  cv::Size size;  // publish at this size (0x0: the simulated camera's)
  std::function<bool()> interrupted;
  std::function<void(const std::string&)> log;
};

struct ServeSummary {
  int frames = 0;    // frames published
  int commands = 0;  // commands received
  bool collided = false;
  std::string collision;
  std::string end;  // why the serve ended
  double sim_time_s = 0.0;
  // The ground truth at the frame of the method's last decision (its status topic), and at the end.
  bool have_decided_pose = false;
  Pose2 decided_pose;
  Pose2 final_pose;
  std::vector<Pose2> path;  // ground truth per frame published
};

ServeSummary ServeSimulation(sim::Simulation& sim, int robot, const robot::RobotFile& file,
                             const ServeOptions& options);

}  // namespace mapless::ros1
