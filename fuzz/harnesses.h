// Fuzz harnesses: one per parser of outside input. Each feeds the bytes to the parser and accepts
// a result or a mapless::InputError (the one way bad input may fail); anything else (a crash, a
// sanitizer report, another exception, a hang) is a bug. The same functions run under libFuzzer
// (fuzz_main.cc, scripts/fuzz.sh) and, on the kept inputs, in the ordinary test suite
// (fuzz_regression_test.cc).
#pragma once

#include <string>
#include <vector>

namespace mapless::fuzz {

using Harness = void (*)(const std::string& input);

struct NamedHarness {
  const char* name;  // the fuzz target is fuzz_<name>; kept inputs live in fuzz/corpus/<name>/
  Harness run;
};

void RouteManifest(const std::string& input);  // route/manifest.json (nlohmann-json)
void RouteKeyframe(const std::string& input);  // route/keyframes/NNNNNN.yml (OpenCV FileStorage)
void Scenario(const std::string& input);       // scenario / world YAML
void Config(const std::string& input);         // run configuration YAML (--config)
void Calibration(const std::string& input);    // planar-flow calibration YAML (navigate)
void Flo(const std::string& input);            // Middlebury .flo
void Tum(const std::string& input);            // TUM trajectory text
void CameraInfo(const std::string& input);     // ROS camera_info YAML (--camera-info)
// The image-folder front end: the input as one to three image files of a folder (split at the
// marker "\xffNXT"), opened and read to the end by io::OpenFrameSource, limits included.
void ImageFolder(const std::string& input);
// The video front end: the input as a video file, opened by io::OpenFrameSource (FFmpeg), read
// for up to 8 frames.
void VideoFile(const std::string& input);
// The scenario-to-world path: a scenario parsed with the world limits, then its world used the way
// the simulator uses it without rendering: object surfaces, collisions and clearance, a driven
// robot for 30 frames, the scenario's area, and the top-down picture.
void ScenarioWorld(const std::string& input);

// The robot file (robot/robot_file.h).
void RobotFile(const std::string& input);
// The appearance route's manifest (route/appearance_store.h).
void AppearanceManifest(const std::string& input);
// A camera message from the network, as the robot links decode it (robot/camera_image.h): the
// first byte chooses a raw Image (0) or a CompressedImage (1); a raw one carries its encoding up to
// a NUL, then width, height and step as 4-byte little-endian numbers, a big-endian flag and the
// data; a compressed one its format up to a NUL, then the data. The frame is then prepared for a
// 320x240 method, upright and turned.
void CameraMessage(const std::string& input);

// A message from the fleet link (fleet/record.h): a follower's subscription, or a leader's record
// decoded and its contents checked as a follower checks them before storing them (the header, an
// eigenspace route image and its entry, a keyframe's YAML and PNG against a 320x240 ORB route).
void FleetRecord(const std::string& input);

// The follower's side of the fleet link: the input as up to 8 messages from a leader (split at
// "\xffNXT"), each decoded and, when it continues the copy, applied to a fresh RouteCopy (in
// /dev/shm: the files are written, as a follower writes them), then the route built from the copy
// as the follower's method asks for it.
void FleetFollower(const std::string& input);
// The leader's side of shared views (issue 45): the input as a message a follower sends, decoded
// and, when it is a view, offered to a leader's complete 3-keyframe route (in /dev/shm), which
// takes it (RouteCopy::TakeView: written, as a leader writes it) or refuses it with one line.
void FleetViewOffer(const std::string& input);
// A ROS 2 sample from the network (issue 40): the first byte chooses the type mapless reads
// (Image, CompressedImage, Odometry, Bool, Clock, Twist, String); the rest is the serialized data
// with its encapsulation header, decoded by Cyclone DDS as a received sample is and used as the
// robot link uses it. Nothing without the ROS 2 link.
void Ros2Message(const std::string& input);

// An MCAP file (recording/mcap_reader.h): every record, chunks opened and every record type
// parsed, then the messages with their channels and schemas.
void McapFile(const std::string& input);
// A ROS 1 bag (rosbag_storage) read to the end, every message decoded by its type, and played as
// a camera source (nothing when mapless was built without ROS 1 bags).
void RosBag(const std::string& input);

// A text message from a live view client (live/protocol.h: issue 43), parsed as the server parses
// it, applied to a client's subscriptions of the run's channels, and answered (a status message
// for what was refused): never an exception, the subscriptions within their bound.
void LiveClientMessage(const std::string& input);
// The bytes a live view client sends on its connection, as up to 16 reads: websocketpp's HTTP
// request parser with the server's body limit, then the handshake's checks and the subprotocol
// chosen (issue 67).
void LiveHttpRequest(const std::string& input);
// The same after the handshake: websocketpp's WebSocket frame parser (hybi13, server side, the
// server's 64 KB message limit), each text message then parsed as the server does.
void LiveWebSocketFrames(const std::string& input);

const std::vector<NamedHarness>& Harnesses();

}  // namespace mapless::fuzz
