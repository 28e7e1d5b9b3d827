// Recordings as camera sources, played like `ros2 bag play`: an MCAP file (ROS 2 messages), a
// ROS 1 bag (when mapless is built with ROS 1), a video file, an image folder, or a camera. Frames
// carry the recording's wheel odometry when it has any (nav_msgs/Odometry), so every method can
// run on a recording as on a robot.
#pragma once

#include <functional>
#include <memory>
#include <string>

#include "mapless/io/frame_source.h"
#include "mapless/robot/link.h"

namespace mapless::recording {

struct PlaybackOptions {
  // The image topic (sensor_msgs/Image or CompressedImage); "": the recording's only one.
  std::string topic;
  // The odometry topic (nav_msgs/Odometry); "": the only one when there is one; "none": none.
  std::string odom_topic;
  // Wall-clock pacing at this multiple of the recorded speed (ros2 bag play --rate); 0: every frame
  // as soon as the previous one was used (the default: nothing is dropped, results do not depend
  // on the machine's speed).
  double rate = 0.0;
  double start_s = 0.0;  // begin this far into the recording (ros2 bag play --start-offset)
  bool loop = false;     // play again from the start; times go on from the end
  double fps = 10.0;     // image folders: their frame rate
  // A TUM trajectory as the odometry of a video's or an image folder's frames (tum_poses.h); "":
  // none. Recordings (.mcap, .bag) have their odometry topic instead.
  std::string poses;
  void Validate() const;
};

// True for the recordings OpenSource reads itself (.mcap, .bag), not through io::OpenFrameSource.
bool IsRecording(const std::string& spec);

// Opens `spec` with the options; throws InputError naming the file, topic or option.
std::unique_ptr<io::FrameSource> OpenSource(const std::string& spec,
                                            const PlaybackOptions& options);

// A recording as a robot link: its frames (with their odometry) go to the loop, the commands go
// nowhere. The link's clock is the frame's time, so no frame is stale. The end of the recording
// closes the link ("end of the recording").
class PlaybackLink : public robot::RobotLink {
 public:
  explicit PlaybackLink(std::unique_ptr<io::FrameSource> source) : source_(std::move(source)) {}
  // Called on every frame before it goes to the loop (with its name, which the observation does
  // not keep); throws to refuse the recording (a frame of the wrong size, say).
  void set_frame_check(std::function<void(const io::Frame&)> check) { check_ = std::move(check); }
  robot::LinkEvent Next() override;
  void Send(const Twist2&, const robot::Observation&, const robot::Decision&) override {}
  void Stop(const std::string&) override {}
  Timestamp now_ns() const override { return now_ns_; }

 private:
  std::unique_ptr<io::FrameSource> source_;
  std::function<void(const io::Frame&)> check_;
  Timestamp now_ns_ = 0;
};
inline constexpr const char* kEndOfRecording = "end of the recording";

// Whether ROS 1 bags can be read (mapless built with librosbag-storage-dev).
bool CanReadBags();

}  // namespace mapless::recording
