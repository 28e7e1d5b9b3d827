// `mapless sim serve`: the simulator as a robot on a middleware. It publishes the simulated camera
// (sensor_msgs/Image, mono8 by default), the wheel odometry (nav_msgs/Odometry, frame `odom`,
// child `base_link`) and, under use_sim_time, the clock; it obeys geometry_msgs/Twist on cmd_vel.
// The loop is written once here; each middleware (ros1/, ros2/) supplies a SimTransport.
//
// Lockstep (use_sim_time): it waits until a method has connected, then publishes one frame, waits
// for the one command the method answers it with, advances one camera period and publishes the
// next: runs are deterministic and as fast as the method. A frame not answered within a second
// (wall time) is sent again with the same stamp (a best-effort camera topic may lose one; the
// link drops a copy it already has). Real time (otherwise): it publishes at the camera rate and,
// like a robot base, stops the robot when no command came for 0.5 s.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <functional>
#include <mutex>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "mapless/robot/robot_file.h"
#include "mapless/sim/simulation.h"

namespace mapless::robot {

// A camera frame as a sensor_msgs/Image (compressed false) or CompressedImage (true: `encoding`
// is the format, width/height/step unused).
struct CameraMessage {
  bool compressed = false;
  std::string encoding;
  std::uint32_t width = 0, height = 0, step = 0;
  std::vector<std::uint8_t> data;
};

// The grey frame at `size` (0x0: as it is) in `encoding`: "mono8", "rgb8", "bgr8" (Image), "jpeg"
// or "png" (CompressedImage); any other name gives an Image with that encoding and two bytes a
// pixel (to test how a method meets an encoding it does not know).
CameraMessage EncodeCamera(const cv::Mat& grey, const std::string& encoding, cv::Size size);

// The camera topic `sim serve` publishes on for an encoding.
std::string ServedCameraTopic(const RobotFile& file, const std::string& encoding);

// The middleware's side of `sim serve`. Its callbacks hand commands and the method's status to
// OnCommand/OnStatus; the loop reads them.
class SimTransport {
 public:
  virtual ~SimTransport() = default;
  // Lockstep: a method subscribes the camera (and the odometry and clock) and publishes commands
  // and its status.
  virtual bool MethodConnected() = 0;
  // Someone still publishes commands.
  virtual bool MethodPresent() = 0;
  virtual bool ok() = 0;
  // The middleware's clock (stamps in real time).
  virtual Timestamp now_ns() = 0;
  // One frame with its odometry (and the clock, when `clock`) stamped `stamp_ns`.
  virtual void Publish(Timestamp stamp_ns, bool clock, const Pose2& odometry,
                       const CameraMessage& image) = 0;

  void OnCommand(Twist2 command);
  void OnStatus(std::string_view json);

  enum class Wait { kCommand, kTimeout, kGone };
  // Waits for a command after the `seen`-th, at most `timeout_s` (wall time).
  Wait WaitCommand(int seen, double timeout_s, const std::function<bool()>& interrupted,
                   Twist2* command);
  int commands();
  Twist2 Latest(double* age_s);
  // The frame time of the method's last decision (-1: none yet).
  Timestamp DecidedAt();

 private:
  std::mutex mutex_;
  std::condition_variable cv_;
  Twist2 last_;
  std::int64_t last_at_ns_ = 0;  // steady clock
  int commands_ = 0;
  Timestamp decided_ns_ = -1;
};

struct ServeOptions {
  double period_s = 0.1;
  double timeout_s = 1e9;          // simulated time: the serve ends
  double command_timeout_s = 0.5;  // real time: no command this long stops the robot
  std::string encoding = "mono8";  // see EncodeCamera
  cv::Size size;                   // publish at this size (0x0: the simulated camera's)
  std::function<bool()> interrupted;
  std::function<void(const std::string&)> log;
  // Each frame served, with the command it was answered with and the true pose (the live view).
  std::function<void(const Observation&, const Twist2&, const Pose2&)> on_step;
};

struct ServeSummary {
  int frames = 0;    // frames published
  int commands = 0;  // commands received
  int resent = 0;    // lockstep frames sent again
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

// The summary as `sim serve --summary` writes it: end, frames, commands, resent, sim_time_s,
// collided (and collision), the final pose and the decided one ({x_m, y_m, theta_deg}; the
// decided one also flat as decided_x_m, decided_y_m, for scripts).
nlohmann::json ServeSummaryJson(const ServeSummary& s);

ServeSummary ServeSimulation(sim::Simulation& sim, int robot, const RobotFile& file,
                             const ServeOptions& options, SimTransport& transport);

}  // namespace mapless::robot
