// The command-line options of recordings: `--record FILE` on any run (recording/run_recorder.h)
// and the `ros2 bag play`-like options of recordings used as sources (recording/playback.h).
#pragma once

#include <CLI/CLI.hpp>
#include <memory>
#include <optional>
#include <string>

#include "mapless/live/live_view.h"
#include "mapless/recording/playback.h"
#include "mapless/recording/run_recorder.h"
#include "mapless/robot/link.h"

namespace mapless::app {

struct RecordArgs {
  std::string path;
  std::string images = "raw";
  std::string compression = "zstd";
  std::string camera_info;  // ROS camera_info YAML: the intrinsics recorded with every frame
  live::LiveArgs live;      // --live [ADDRESS:]PORT, --live-rate: the live view
};

// --record FILE, --record-images raw|png|jpeg, --record-compression zstd|lz4|none,
// --camera-info FILE.yaml, --live [ADDRESS:]PORT.
void AddRecordOptions(CLI::App* cmd, RecordArgs* args);

// --topic, --odom-topic, --start, --loop, and --rate unless `with_rate` is false (a command whose
// --rate means something else).
void AddPlaybackOptions(CLI::App* cmd, recording::PlaybackOptions* options, bool with_rate = true);

// The recorder --record asks for (nullptr without it). Created before the run starts, so a bad
// path fails before anything moves. `camera_info`: the intrinsics where mapless knows them (the
// simulator); --camera-info FILE.yaml replaces them.
std::unique_ptr<recording::RunRecorder> OpenRecorder(
    const RecordArgs& args, std::optional<rosmsg::CameraInfoFields> camera_info = std::nullopt);

// --live [ADDRESS:]PORT, and --live-rate unless the command paces itself (AddRecordOptions: both).
void AddLiveOption(CLI::App* cmd, live::LiveArgs* args, bool with_rate = true);

// The live view --live asks for (nullptr without), serving before the run starts; `simulated`:
// paced while watched; `route`: the taught route's poses in its odometry frame.
std::unique_ptr<live::LiveView> OpenLive(const live::LiveArgs& args, const char* method,
                                         bool simulated, std::vector<Pose2> route = {});

// A link wrapper that records through `recorder` and shows the run in `live` (each if not null).
robot::LinkWrapper RecordingWrapper(recording::RunRecorder* recorder, const char* method,
                                    live::LiveView* live = nullptr);

}  // namespace mapless::app
