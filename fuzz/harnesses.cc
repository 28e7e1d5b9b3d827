#include "harnesses.h"

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <memory>
#include <opencv2/core/utils/logger.hpp>
#include <opencv2/imgcodecs.hpp>

#include "mapless/core/check.h"
#include "mapless/fleet/record.h"
#include "mapless/fleet/route_log.h"
#include "mapless/io/flo.h"
#include "mapless/io/frame_source.h"
#include "mapless/io/image_file.h"
#include "mapless/io/tum.h"
#include "mapless/live/feed.h"
#include "mapless/live/protocol.h"
#include "mapless/navigation/potential.h"
#include "mapless/recording/bag_check.h"
#include "mapless/recording/camera_info_yaml.h"
#include "mapless/recording/mcap_reader.h"
#include "mapless/recording/mcap_source.h"
#include "mapless/robot/camera_image.h"
#include "mapless/robot/robot_file.h"
#include "mapless/rosmsg/messages.h"
#include "mapless/route/appearance_store.h"
#include "mapless/route/route_store.h"
#include "mapless/sim/driver.h"
#include "mapless/sim/renderer.h"
#include "mapless/sim/scenario.h"
#include "mapless/sim/simulation.h"
#include "mapless/viz/topdown.h"

namespace mapless::fuzz {
namespace {

template <typename F>
void AcceptInputError(F&& parse) {
  try {
    parse();
  } catch (const InputError&) {
    // Bad input, reported as it should be.
  }
}

}  // namespace

void RouteManifest(const std::string& input) {
  AcceptInputError([&] { route::ParseManifest(input, "fuzz/manifest.json"); });
}

void RouteKeyframe(const std::string& input) {
  AcceptInputError([&] { route::ParseKeyframe(input, "fuzz/000000.yml"); });
}

void Scenario(const std::string& input) {
  // World files named by the scenario resolve against a directory that does not exist.
  AcceptInputError([&] { sim::ParseScenario(input, "fuzz.yaml", "/nonexistent-mapless-fuzz"); });
}

void Config(const std::string& input) {
  AcceptInputError([&] { sim::ParseDriveOptions(input, "fuzz.yaml"); });
}

void Calibration(const std::string& input) {
  AcceptInputError([&] { navigation::CalibrationFromYaml(input, "fuzz.yaml"); });
}

void Flo(const std::string& input) {
  AcceptInputError([&] { io::ParseFlo(input, "fuzz.flo"); });
}

void Tum(const std::string& input) {
  AcceptInputError([&] { io::ParseTum(input, "fuzz.txt"); });
}

void CameraInfo(const std::string& input) {
  rosmsg::CameraInfoFields info;
  try {
    info = recording::ParseCameraInfoYaml(input, "fuzz.yaml");
  } catch (const InputError&) {
    return;
  }
  // What mapless writes it reads back, the same (an InputError here is a bug: it escapes).
  const rosmsg::CameraInfoFields again =
      recording::ParseCameraInfoYaml(recording::FormatCameraInfoYaml(info), "again.yaml");
  if (again.k != info.k || again.d != info.d || again.r != info.r || again.p != info.p ||
      again.width != info.width || again.height != info.height ||
      again.distortion_model != info.distortion_model) {
    std::abort();
  }
}

namespace {

// A scratch directory of this process's own, emptied for each input.
std::filesystem::path Scratch(const char* what) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() /
                                    ("mapless-fuzz-" + std::to_string(::getpid()) + "-" + what);
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

void WriteBytes(const std::filesystem::path& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

void ReadAll(io::FrameSource* source, int max_frames) {
  io::Frame frame;
  for (int i = 0; i < max_frames && source->Next(&frame); ++i) {
    if (frame.image.empty() || frame.image.type() != CV_8UC1) std::abort();  // never garbage
  }
}

}  // namespace

void ImageFolder(const std::string& input) {
  const std::filesystem::path dir = Scratch("folder");
  static const std::string kMarker = "\xffNXT";
  std::size_t from = 0;
  for (int i = 0; i < 3; ++i) {
    const std::size_t at = input.find(kMarker, from);
    const std::size_t end = at == std::string::npos || i == 2 ? input.size() : at;
    WriteBytes(dir / ("frame" + std::to_string(i) + ".png"), input.substr(from, end - from));
    if (end == input.size()) break;
    from = end + kMarker.size();
  }
  AcceptInputError([&] {
    const auto source = io::OpenFrameSource(dir.string(), 10.0);
    ReadAll(source.get(), 3);
  });
  std::filesystem::remove_all(dir);
}

void VideoFile(const std::string& input) {
  // As in the command line: OpenCV's own log lines are off (they would flood the fuzzer's output).
  static const bool quiet = [] {
    cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_SILENT);
    return true;
  }();
  (void)quiet;
  const std::filesystem::path dir = Scratch("video");
  const std::filesystem::path file = dir / "video.avi";
  WriteBytes(file, input);
  AcceptInputError([&] {
    const auto source = io::OpenFrameSource(file.string(), 10.0);
    ReadAll(source.get(), 8);
  });
  std::filesystem::remove_all(dir);
}

void ScenarioWorld(const std::string& input) {
  AcceptInputError([&] {
    const sim::Scenario scenario =
        sim::ParseScenario(input, "fuzz.yaml", "/nonexistent-mapless-fuzz");
    for (const sim::WorldObject& o : scenario.world.objects) {
      std::vector<sim::Surface> surfaces;
      sim::AppendObjectSurfaces(o, nullptr, &surfaces, sim::LightDirection(scenario.world));
    }
    sim::Simulation simulation(scenario.world, scenario.camera, sim::SimulationOptions{},
                               scenario.seed);
    const int robot = simulation.AddRobot(scenario.teach_start, scenario.robot);
    sim::ScriptedDriver driver(scenario.teach_start, scenario.teach_path, scenario.teach_speed_mps);
    for (int frame = 0; frame < 30 && !driver.done(); ++frame) {
      simulation.SetCommand(robot, driver.Update(simulation.robot(robot).pose()));
      simulation.Advance(1.0 / scenario.camera.rate_hz);
    }
    const Eigen::Vector4d area = sim::ScenarioBounds(scenario, 5.0);
    (void)sim::ClearanceTo(scenario.world, area[0], area[1]);
    viz::TopDownOptions small;
    small.max_side_px = 200;
    (void)viz::DrawTopDown(scenario.world, {}, scenario.destinations, small);
    (void)scenario.PathLength();
  });
}

void RobotFile(const std::string& input) {
  AcceptInputError([&] { robot::ParseRobotFile(input, "fuzz_robot.yaml"); });
}

void AppearanceManifest(const std::string& input) {
  AcceptInputError([&] {
    std::vector<std::string> files;
    route::ParseAppearanceManifest(input, "fuzz/appearance.json", &files);
  });
}

void CameraMessage(const std::string& input) {
  if (input.empty()) return;
  const std::size_t nul = input.find('\0', 1);
  if (nul == std::string::npos || nul > 64) return;
  const std::string label = input.substr(1, nul - 1);
  std::string_view rest(input);
  rest.remove_prefix(nul + 1);
  AcceptInputError([&] {
    cv::Mat grey;
    if (input[0] == 1) {
      grey = robot::GreyFromCompressed(label, rest);
    } else {
      if (rest.size() < 13) return;
      auto u32 = [&](std::size_t at) {
        std::uint32_t v = 0;
        for (int b = 3; b >= 0; --b) v = (v << 8) | static_cast<unsigned char>(rest[at + b]);
        return v;
      };
      const std::uint32_t w = u32(0), h = u32(4), step = u32(8);
      const bool big = rest[12] != 0;
      rest.remove_prefix(13);
      grey = robot::GreyFromRaw(label, w, h, step, big, rest);
    }
    robot::PrepareFrame(grey, robot::CameraMount::kRotated180, cv::Size(320, 240));
  });
}

void FleetRecord(const std::string& input) {
  AcceptInputError([&] { fleet::DecodeSubscribe(input); });
  AcceptInputError([&] {
    const fleet::Record r = fleet::DecodeRecord(input);
    if (r.type == fleet::RecordType::kHeader) {
      fleet::ParseHeader(r);
    } else if (r.type == fleet::RecordType::kImage) {
      route::ParseAppearanceEntry(r.parts[0], "fuzz record");
      io::DecodeImage(r.parts[1], "fuzz record", cv::IMREAD_GRAYSCALE);
    } else if (r.type == fleet::RecordType::kKeyframe) {
      route::Manifest header;
      header.detector = "orb";
      header.image_width = 320;
      header.image_height = 240;
      route::DecodeKeyframe(r.parts[0], r.parts[1], header, 0, 0, "fuzz record");
    }
  });
}

// A leader's route for FleetViewOffer: 3 keyframes of 40 ORB-sized features, 320x240, complete.
std::unique_ptr<fleet::RouteCopy> FuzzLeaderRoute(const std::filesystem::path& dir) {
  std::error_code ec;
  std::filesystem::remove_all(dir, ec);
  auto copy = std::make_unique<fleet::RouteCopy>(dir.string());
  fleet::RouteHeader h;
  h.image_width = 320;
  h.image_height = 240;
  std::vector<fleet::Record> records = {fleet::HeaderRecord(h)};
  for (int k = 0; k < 3; ++k) {
    route::Keyframe kf;
    kf.index = k;
    kf.t_ns = 100'000'000LL * (k + 1);
    kf.thumbnail = cv::Mat(60, 80, CV_8UC1, cv::Scalar(40 * k));
    kf.descriptors = cv::Mat(40, 32, CV_8UC1);
    for (int i = 0; i < 40; ++i) {
      kf.keypoints.emplace_back(static_cast<float>(7 * i % 320), static_cast<float>(11 * i % 240),
                                31.0f);
      for (int c = 0; c < 32; ++c)
        kf.descriptors.at<std::uint8_t>(i, c) = static_cast<std::uint8_t>(i * 31 + c * 7 + k);
    }
    records.push_back(fleet::KeyframeRecord(kf));
  }
  records.push_back(fleet::EndRecord());
  for (std::size_t i = 0; i < records.size(); ++i) records[i].sequence = i;
  copy->Apply(records);
  return copy;
}

void FleetViewOffer(const std::string& input) {
  static const std::filesystem::path dir = [] {
    const std::filesystem::path shm("/dev/shm");
    return (std::filesystem::is_directory(shm) ? shm : std::filesystem::temp_directory_path()) /
           ("mapless-fuzz-leader-" + std::to_string(::getpid()));
  }();
  static std::unique_ptr<fleet::RouteCopy> leader;
  if (!leader || leader->next_sequence() != 5) {  // a view taken: back to the bare route
    leader.reset();
    leader = FuzzLeaderRoute(dir);
  }
  AcceptInputError([&] {
    const fleet::Record r = fleet::DecodeRecord(input);
    if (r.type != fleet::RecordType::kView) return;
    leader->TakeView(r, 3);
    const std::vector<fleet::Record> log = leader->RecordsFrom(5, 1);
    if (log.size() != 1 || log[0].type != fleet::RecordType::kView) std::abort();
    const std::shared_ptr<const route::Route> route = leader->FunnelRoute();
    if (!route || route->visits != 1) std::abort();  // the view taken is visit 1
  });
}

void FleetFollower(const std::string& input) {
  static const std::filesystem::path dir = [] {
    const std::filesystem::path shm("/dev/shm");
    return (std::filesystem::is_directory(shm) ? shm : std::filesystem::temp_directory_path()) /
           ("mapless-fuzz-follower-" + std::to_string(::getpid()));
  }();
  std::error_code ec;
  std::filesystem::remove_all(dir, ec);
  std::vector<std::string> messages;
  std::size_t from = 0;
  while (messages.size() < 8) {
    const std::size_t at = input.find("\xffNXT", from);
    messages.push_back(input.substr(from, at == std::string::npos ? std::string::npos : at - from));
    if (at == std::string::npos) break;
    from = at + 4;
  }
  AcceptInputError([&] {
    fleet::RouteCopy copy(dir.string());
    for (const std::string& m : messages) {
      AcceptInputError([&] {
        const fleet::Record r = fleet::DecodeRecord(m);
        if (r.type == fleet::RecordType::kHeartbeat || r.sequence != copy.next_sequence()) return;
        copy.Apply({r});
      });
    }
    AcceptInputError([&] { copy.FunnelRoute(); });
    AcceptInputError([&] { copy.AppearanceRoute(); });
  });
  std::filesystem::remove_all(dir, ec);
}

#ifndef MAPLESS_FUZZ_ROS2
void Ros2Message(const std::string&) {}  // built without the ROS 2 link
#endif

// Every message of a recording through the reader of its type (ROS 1 or ROS 2 wire).
void DecodeEveryMessage(std::unique_ptr<recording::MessageStream> messages) {
  recording::RecordedMessage m;
  for (int n = 0; n < 100'000 && messages->Next(&m); ++n) {
    const std::string& type = m.topic->type;
    AcceptInputError([&] {
      if (type == "sensor_msgs/msg/Image") {
        const rosmsg::ImageFields im = rosmsg::DecodeImage(m.data, m.wire);
        robot::GreyFromRaw(im.encoding, im.width, im.height, im.step, im.big_endian, im.data);
      } else if (type == "sensor_msgs/msg/CompressedImage") {
        rosmsg::DecodeCompressedImage(m.data, m.wire);
      } else if (type == "sensor_msgs/msg/CameraInfo") {
        rosmsg::DecodeCameraInfo(m.data, m.wire);
      } else if (type == "geometry_msgs/msg/Twist") {
        rosmsg::DecodeTwist(m.data, m.wire);
      } else if (type == "nav_msgs/msg/Odometry") {
        rosmsg::DecodeOdometry(m.data, m.wire);
      } else if (type == "geometry_msgs/msg/PoseStamped") {
        rosmsg::DecodePoseStamped(m.data, m.wire);
      }
    });
  }
}

void PlayFrames(std::unique_ptr<io::FrameSource> source) {
  io::Frame frame;
  for (int n = 0; n < 1000 && source->Next(&frame); ++n) {
  }
}

void McapFile(const std::string& input) {
  AcceptInputError([&] {
    const std::unique_ptr<recording::McapReader> reader =
        recording::McapReader::FromBytes(input, "fuzz.mcap");
    using recording::McapOp;
    reader->ForEachRecord([](std::uint8_t op, std::string_view body, std::uint64_t) {
      switch (static_cast<McapOp>(op)) {
        case McapOp::kHeader:
          recording::ParseMcapHeader(body);
          break;
        case McapOp::kFooter:
          recording::ParseMcapFooter(body);
          break;
        case McapOp::kSchema:
          recording::ParseMcapSchema(body);
          break;
        case McapOp::kChannel:
          recording::ParseMcapChannel(body);
          break;
        case McapOp::kMessage:
          recording::ParseMcapMessage(body);
          break;
        case McapOp::kMessageIndex:
          recording::ParseMcapMessageIndex(body);
          break;
        case McapOp::kChunkIndex:
          recording::ParseMcapChunkIndex(body);
          break;
        case McapOp::kAttachment:
          recording::ParseMcapAttachment(body);
          break;
        case McapOp::kAttachmentIndex:
          recording::ParseMcapAttachmentIndex(body);
          break;
        case McapOp::kStatistics:
          recording::ParseMcapStatistics(body);
          break;
        case McapOp::kMetadata:
          recording::ParseMcapMetadata(body);
          break;
        case McapOp::kMetadataIndex:
          recording::ParseMcapMetadataIndex(body);
          break;
        case McapOp::kSummaryOffset:
          recording::ParseMcapSummaryOffset(body);
          break;
        case McapOp::kDataEnd:
          recording::ParseMcapDataEnd(body);
          break;
        default:
          break;
      }
    });
  });
  AcceptInputError([&] {
    recording::McapReader::FromBytes(input, "fuzz.mcap")
        ->ForEachMessage([](const recording::McapChannel&, const recording::McapSchema*,
                            const recording::McapMessage&) {});
  });
  // As a recording played back: its topics, every message decoded by its type, its frames.
  const std::filesystem::path path = Scratch("mcap") / "fuzz.mcap";
  WriteBytes(path, input);
  AcceptInputError([&] { DecodeEveryMessage(recording::OpenMcapMessages(path.string())); });
  AcceptInputError([&] { PlayFrames(recording::OpenMcapSource(path.string(), "", "")); });
}

// rosbag_storage loads its encryptor plugin (pluginlib: dlopen, package index) on every open,
// which bounds this target to about 50 inputs a second. Only bags that pass the structure check
// (bag_check.h: the part that reads untrusted lengths for the library) reach the library, and
// only once: messages decoded by type and frames played from the same stream.
void RosBag(const std::string& input) {
  if (!recording::CanReadBagsImpl()) return;
  const std::filesystem::path path = Scratch("bag") / "fuzz.bag";
  WriteBytes(path, input);
  bool sound = false;
  AcceptInputError([&] {
    recording::CheckBagStructure(path.string());
    sound = true;
  });
  if (!sound) return;
  AcceptInputError([&] { PlayFrames(recording::OpenBagSource(path.string(), "", "")); });
}

void LiveClientMessage(const std::string& input) {
  static const std::vector<std::uint32_t> channels = [] {
    std::vector<std::uint32_t> ids;
    for (const live::Channel& c : live::RunChannels("follow", true)) ids.push_back(c.id);
    return ids;
  }();
  live::Subscriptions subscriptions(16);
  // The input as up to 8 messages of one client (split at "\xffNXT").
  std::size_t start = 0;
  for (int i = 0; i < 8 && start <= input.size(); ++i) {
    const std::size_t end = std::min(input.find("\xffNXT", start), input.size());
    const live::ClientRequest r =
        live::ParseClientMessage(std::string_view(input).substr(start, end - start));
    if ((r.kind == live::ClientRequest::Kind::kInvalid ||
         r.kind == live::ClientRequest::Kind::kUnsupported) &&
        r.error.empty())
      std::abort();  // every refusal says why
    for (const std::string& refused : subscriptions.Apply(r, channels))
      (void)live::StatusJson(1, refused);
    (void)live::StatusJson(2, r.error);
    if (subscriptions.size() > 16) std::abort();
    for (const std::uint32_t id : channels)
      if (subscriptions.For(id).size() > 1) std::abort();  // a channel is subscribed once
    start = end + 4;
  }
}

const std::vector<NamedHarness>& Harnesses() {
  static const std::vector<NamedHarness> harnesses = {{"route_manifest", RouteManifest},
                                                      {"route_keyframe", RouteKeyframe},
                                                      {"scenario", Scenario},
                                                      {"config", Config},
                                                      {"calibration", Calibration},
                                                      {"flo", Flo},
                                                      {"tum", Tum},
                                                      {"image_folder", ImageFolder},
                                                      {"video_file", VideoFile},
                                                      {"scenario_world", ScenarioWorld},
                                                      {"robot_file", RobotFile},
                                                      {"appearance_manifest", AppearanceManifest},
                                                      {"camera_message", CameraMessage},
                                                      {"fleet_record", FleetRecord},
                                                      {"fleet_follower", FleetFollower},
                                                      {"fleet_view_offer", FleetViewOffer},
                                                      {"ros2_message", Ros2Message},
                                                      {"mcap", McapFile},
                                                      {"rosbag", RosBag},
                                                      {"camera_info", CameraInfo},
                                                      {"live_client", LiveClientMessage},
                                                      {"live_http", LiveHttpRequest},
                                                      {"live_ws_frames", LiveWebSocketFrames}};
  return harnesses;
}

}  // namespace mapless::fuzz
