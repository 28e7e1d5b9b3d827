// What the live view shows of a run, as messages of its channels: the camera image and the
// method's debug picture (sensor_msgs/msg/CompressedImage, ROS 2 CDR, the bytes a recording
// holds), the decision of every frame as JSON with its JSON Schema (Foxglove's Plot and State
// Transitions panels read it), the odometry and the command (nav_msgs/msg/Odometry,
// geometry_msgs/msg/Twist), the robot on its route from above (/tf as foxglove.FrameTransforms,
// the driven path and the taught route as foxglove.PosesInFrame, REP-105 frames odom -> base_link)
// and, for the appearance follower, the localization belief over the route images.
//
// Pure: a frame in, messages out. The server (server.h) calls it on its own thread, so the
// images are encoded off the robot's loop.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "mapless/core/pose.h"
#include "mapless/live/protocol.h"
#include "mapless/robot/method.h"

namespace mapless::live {

enum ChannelId : std::uint32_t {
  kCameraChannel = 1,
  kDebugChannel = 2,
  kDecisionChannel = 3,
  kTfChannel = 4,
  kPathChannel = 5,
  kRouteChannel = 6,
  kOdomChannel = 7,
  kCmdVelChannel = 8,
  kBeliefChannel = 9,
};

// Channels whose messages may be dropped for a slow client (the newest wins).
bool IsImageChannel(std::uint32_t channel_id);

// The channels of a run of `method` ("teach", "repeat", "navigate", "follow"): the belief only for
// "follow", the route only when `has_route`.
std::vector<Channel> RunChannels(const std::string& method, bool has_route);

// One decision of the run, as the loop handed it over (the image is the loop's own copy).
struct FrameView {
  std::string method;
  int frame = 0;
  robot::Observation observation;
  robot::Decision decision;
  Twist2 command;
  std::optional<Pose2> truth;  // the simulator's true pose
  std::string stop_reason;     // a stop no frame decided (no camera, interrupted): no image
};

struct Outgoing {
  std::uint32_t channel_id = 0;
  std::string payload;
};

struct FeedOptions {
  int jpeg_quality = 80;
  // The driven path keeps a pose every this many metres or radians, at most max_path_poses (then
  // every other pose is dropped).
  double path_step_m = 0.05;
  double path_step_rad = 0.09;
  std::size_t max_path_poses = 2000;
  int path_every_frames = 5;  // the path is sent every this many frames (and on a stop)
};

class Feed {
 public:
  // `route`: the taught route's poses in the odometry frame of its teach (empty: none).
  Feed(std::vector<Pose2> route, FeedOptions options = {});
  // The messages of one frame (or stop), in channel order.
  std::vector<Outgoing> Messages(const FrameView& frame);
  // The messages a client that just subscribed should get at once (the route, the path so far).
  std::vector<Outgoing> Latched(Timestamp t_ns) const;

 private:
  std::string PosesMessage(const std::vector<Pose2>& poses, Timestamp t_ns) const;
  void AddToPath(const Pose2& pose);

  std::vector<Pose2> route_;
  FeedOptions options_;
  std::vector<Pose2> path_;
  int frames_ = 0;
};

}  // namespace mapless::live
