// A run recorded as ROS 2 messages in MCAP, on the topics a ROS 2 robot uses (REP-103/105 frames),
// so that Foxglove, Lichtblick and `ros2 bag` open it and mapless replays it:
//
//   /camera/image_raw             sensor_msgs/msg/Image (mono8), or
//   /camera/image_raw/compressed  sensor_msgs/msg/CompressedImage (png or jpeg)
//   /camera/camera_info           sensor_msgs/msg/CameraInfo (when the intrinsics are known)
//   /cmd_vel                      geometry_msgs/msg/Twist
//   /odom                         nav_msgs/msg/Odometry (frame odom, child base_link)
//   /ground_truth                 geometry_msgs/msg/PoseStamped (frame world; the simulator)
//   /mapless/decision             the method's decision per frame, JSON (robot/status.h)
//
// A channel appears with its first message. Log and publish time are the frame's time.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <optional>
#include <string>

#include "mapless/core/pose.h"
#include "mapless/recording/mcap_writer.h"
#include "mapless/rosmsg/messages.h"

namespace mapless::recording {

inline constexpr const char* kImageTopic = "/camera/image_raw";
inline constexpr const char* kCompressedImageTopic = "/camera/image_raw/compressed";
inline constexpr const char* kCameraInfoTopic = "/camera/camera_info";
inline constexpr const char* kCmdVelTopic = "/cmd_vel";
inline constexpr const char* kOdomTopic = "/odom";
inline constexpr const char* kGroundTruthTopic = "/ground_truth";
inline constexpr const char* kDecisionTopic = "/mapless/decision";

struct RunRecorderOptions {
  std::string images = "raw";  // raw (Image, mono8), png or jpeg (CompressedImage)
  int jpeg_quality = 90;
  McapWriterOptions mcap;
  // The camera's intrinsics, recorded with every image when known.
  std::optional<rosmsg::CameraInfoFields> camera_info;
  void Validate() const;
};

class RunRecorder {
 public:
  // Creates `path` (InputError when it exists).
  RunRecorder(const std::string& path, RunRecorderOptions options);
  ~RunRecorder();
  RunRecorder(const RunRecorder&) = delete;
  RunRecorder& operator=(const RunRecorder&) = delete;

  void Image(Timestamp t_ns, const cv::Mat& grey);  // with the camera info, when known
  void Command(Timestamp t_ns, const Twist2& command);
  void Odometry(Timestamp t_ns, const Pose2& pose);
  void GroundTruth(Timestamp t_ns, const Pose2& pose);
  void Decision(Timestamp t_ns, const nlohmann::json& decision);
  void Close();  // summary and footer; the destructor does it too
  std::uint64_t messages() const { return writer_.messages(); }

 private:
  std::uint16_t Channel(const std::string& topic, const std::string& type);
  void Write(const std::string& topic, const std::string& type, Timestamp t_ns,
             std::string_view data);

  RunRecorderOptions options_;
  McapWriter writer_;
  std::map<std::string, std::uint16_t> schemas_;   // by type
  std::map<std::string, std::uint16_t> channels_;  // by topic
};

}  // namespace mapless::recording
