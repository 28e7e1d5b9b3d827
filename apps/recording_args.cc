#include "recording_args.h"

#include <spdlog/spdlog.h>

#include "cli_common.h"
#include "mapless/core/check.h"
#include "mapless/recording/camera_info_yaml.h"
#include "mapless/recording/recording_link.h"

namespace mapless::app {

void AddRecordOptions(CLI::App* cmd, RecordArgs* args) {
  cmd->add_option("--record", args->path,
                  "Record the run to this MCAP file (ROS 2 messages: camera, camera_info, "
                  "cmd_vel, odom, ground truth, decisions); Foxglove and ros2 bag open it, "
                  "mapless replays it as a --source");
  cmd->add_option("--record-images", args->images,
                  "raw (sensor_msgs/Image), png or jpeg (CompressedImage)")
      ->capture_default_str()
      ->check(CLI::IsMember({"raw", "png", "jpeg"}));
  cmd->add_option("--record-compression", args->compression, "MCAP chunks: zstd, lz4 or none")
      ->capture_default_str()
      ->check(CLI::IsMember({"zstd", "lz4", "none"}));
  cmd->add_option("--camera-info", args->camera_info,
                  "With --record: the camera's intrinsics (ROS camera_info YAML, as "
                  "camera_calibration writes it), recorded as sensor_msgs/CameraInfo with every "
                  "frame");
  AddLiveOption(cmd, &args->live);
}

void AddLiveOption(CLI::App* cmd, live::LiveArgs* args, bool with_rate) {
  if (with_rate)
    cmd->add_option("--live-rate", args->rate,
                    "The simulator, while someone watches --live: simulated seconds per second "
                    "(0: as fast as it runs)")
        ->capture_default_str()
        ->check(ZeroOrIn(0.01, 1000.0));
  cmd->add_option("--live", args->address,
                  "Watch the run live: [ADDRESS:]PORT (address 127.0.0.1 unless given) serves "
                  "the Foxglove WebSocket protocol (Foxglove, Lichtblick) and a page at "
                  "http://ADDRESS:PORT/ (docs/live_view.md)");
}

void AddPlaybackOptions(CLI::App* cmd, recording::PlaybackOptions* options, bool with_rate) {
  cmd->add_option("--topic", options->topic,
                  "Recordings (.mcap, .bag): the camera topic (default: the only one)");
  cmd->add_option("--odom-topic", options->odom_topic,
                  "Recordings: the nav_msgs/Odometry topic (default: the only one, if any; none: "
                  "no odometry)");
  if (with_rate) {
    cmd->add_option("--rate", options->rate,
                    "Play the source at this multiple of its recorded speed (0: each frame as "
                    "soon as the previous one is used)")
        ->capture_default_str()
        ->check(ZeroOrIn(0.001, 1000.0));
  }
  cmd->add_option("--start", options->start_s, "Begin this many seconds into the source")
      ->capture_default_str()
      ->check(FiniteIn(0.0, 1e9));
  cmd->add_flag("--loop", options->loop, "Play the source again from the start when it ends");
  cmd->add_option("--poses", options->poses,
                  "Videos and image folders: a TUM trajectory (timestamp tx ty tz qx qy qz qw) "
                  "as the frames' odometry, e.g. the odometry.tum beside a sim drive's frames/");
}

std::unique_ptr<recording::RunRecorder> OpenRecorder(
    const RecordArgs& args, std::optional<rosmsg::CameraInfoFields> camera_info) {
  if (args.path.empty()) {
    if (!args.camera_info.empty())
      throw InputError("--camera-info " + args.camera_info +
                       ": the intrinsics go into recordings; give --record FILE.mcap too");
    return nullptr;
  }
  if (!args.camera_info.empty()) camera_info = recording::LoadCameraInfoYaml(args.camera_info);
  recording::RunRecorderOptions options;
  options.images = args.images;
  options.mcap.compression = args.compression == "none" ? "" : args.compression;
  options.camera_info = std::move(camera_info);
  auto recorder = std::make_unique<recording::RunRecorder>(args.path, options);
  spdlog::info("recording to {}", args.path);
  return recorder;
}

std::unique_ptr<live::LiveView> OpenLive(const live::LiveArgs& args, const char* method,
                                         bool simulated, std::vector<Pose2> route) {
  return live::OpenLiveView(args, method, std::move(route), simulated,
                            [](const std::string& line) { spdlog::info("{}", line); });
}

robot::LinkWrapper RecordingWrapper(recording::RunRecorder* recorder, const char* method,
                                    live::LiveView* live) {
  robot::LinkWrapper record;
  if (recorder)
    record = [recorder, method](robot::RobotLink& inner) -> std::unique_ptr<robot::RobotLink> {
      return std::make_unique<recording::RecordingLink>(inner, *recorder, method);
    };
  return live::LiveWrapper(live, record);
}

}  // namespace mapless::app
