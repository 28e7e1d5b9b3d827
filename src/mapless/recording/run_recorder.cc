#include "mapless/recording/run_recorder.h"

#include <algorithm>
#include <opencv2/imgcodecs.hpp>

#include "mapless/core/check.h"
#include "mapless/io/lazy_libraries.h"
#include "mapless/rosmsg/definitions.h"

namespace mapless::recording {

namespace {

constexpr const char* kJson = "json";

// JSON Schema of a decision (robot/status.h): an object; the fields every method writes.
constexpr const char* kDecisionSchema = R"({"type":"object","title":"mapless decision",)"
                                        R"("properties":{"t_s":{"type":"number"},)"
                                        R"("method":{"type":"string"},"state":{"type":"string"},)"
                                        R"("status":{"type":"string"},"reason":{"type":"string"},)"
                                        R"("v_mps":{"type":"number"},)"
                                        R"("omega_radps":{"type":"number"}}})";

std::string_view View(const std::vector<std::uint8_t>& b) {
  return {reinterpret_cast<const char*>(b.data()), b.size()};
}

std::uint64_t LogTime(Timestamp t_ns) {
  return static_cast<std::uint64_t>(std::max<Timestamp>(t_ns, 0));
}

}  // namespace

void RunRecorderOptions::Validate() const {
  if (images != "raw" && images != "png" && images != "jpeg")
    throw InputError("--record-images " + images + ": expected raw, png or jpeg");
  MAPLESS_CHECK(jpeg_quality >= 1 && jpeg_quality <= 100,
                "RunRecorderOptions.jpeg_quality = " << jpeg_quality << "; must be in [1, 100]");
}

RunRecorder::RunRecorder(const std::string& path, RunRecorderOptions options)
    : options_((options.Validate(), std::move(options))), writer_(path, options_.mcap) {}

RunRecorder::~RunRecorder() = default;

std::uint16_t RunRecorder::Channel(const std::string& topic, const std::string& type) {
  if (auto it = channels_.find(topic); it != channels_.end()) return it->second;
  auto schema = schemas_.find(type);
  if (schema == schemas_.end()) {
    const std::uint16_t id =
        type == kJson ? writer_.AddSchema("mapless/Decision", "jsonschema", kDecisionSchema)
                      : writer_.AddSchema(type, "ros2msg", rosmsg::ConcatenatedDefinition(type));
    schema = schemas_.emplace(type, id).first;
  }
  const std::uint16_t id =
      writer_.AddChannel(schema->second, topic, type == kJson ? "json" : "cdr");
  channels_.emplace(topic, id);
  return id;
}

void RunRecorder::Write(const std::string& topic, const std::string& type, Timestamp t_ns,
                        std::string_view data) {
  const std::uint16_t channel = Channel(topic, type);
  writer_.Write(channel, LogTime(t_ns), LogTime(t_ns), data);
}

void RunRecorder::Image(Timestamp t_ns, const cv::Mat& grey) {
  MAPLESS_CHECK(grey.type() == CV_8UC1, "RunRecorder::Image: expected 8-bit grey");
  const rosmsg::Header header{t_ns, "camera"};
  if (options_.images == "raw") {
    const cv::Mat packed = grey.isContinuous() ? grey : grey.clone();
    rosmsg::ImageFields m;
    m.header = header;
    m.height = static_cast<std::uint32_t>(packed.rows);
    m.width = static_cast<std::uint32_t>(packed.cols);
    m.encoding = "mono8";
    m.step = static_cast<std::uint32_t>(packed.cols);
    m.data = {reinterpret_cast<const char*>(packed.data), packed.total()};
    Write(kImageTopic, "sensor_msgs/msg/Image", t_ns, View(rosmsg::EncodeImage(m)));
  } else {
    std::vector<std::uint8_t> encoded;
    const std::vector<int> params =
        options_.images == "jpeg"
            ? std::vector<int>{cv::IMWRITE_JPEG_QUALITY, options_.jpeg_quality}
            : std::vector<int>{};
    io::lazy::ImEncode(options_.images == "jpeg" ? ".jpg" : ".png", grey, &encoded, params);
    rosmsg::CompressedImageFields m;
    m.header = header;
    m.format = options_.images;
    m.data = View(encoded);
    Write(kCompressedImageTopic, "sensor_msgs/msg/CompressedImage", t_ns,
          View(rosmsg::EncodeCompressedImage(m)));
  }
  if (options_.camera_info) {
    rosmsg::CameraInfoFields info = *options_.camera_info;
    if (info.width != static_cast<std::uint32_t>(grey.cols) ||
        info.height != static_cast<std::uint32_t>(grey.rows)) {
      throw InputError("camera info: the intrinsics are for " + std::to_string(info.width) + "x" +
                       std::to_string(info.height) + " images but the camera's are " +
                       std::to_string(grey.cols) + "x" + std::to_string(grey.rows));
    }
    info.header = header;
    Write(kCameraInfoTopic, "sensor_msgs/msg/CameraInfo", t_ns,
          View(rosmsg::EncodeCameraInfo(info)));
  }
}

void RunRecorder::Command(Timestamp t_ns, const Twist2& command) {
  Write(kCmdVelTopic, "geometry_msgs/msg/Twist", t_ns, View(rosmsg::EncodeTwist(command)));
}

void RunRecorder::Odometry(Timestamp t_ns, const Pose2& pose) {
  rosmsg::OdometryFields m;
  m.header = {t_ns, "odom"};
  m.child_frame_id = "base_link";
  m.pose = pose;
  Write(kOdomTopic, "nav_msgs/msg/Odometry", t_ns, View(rosmsg::EncodeOdometry(m)));
}

void RunRecorder::GroundTruth(Timestamp t_ns, const Pose2& pose) {
  Write(kGroundTruthTopic, "geometry_msgs/msg/PoseStamped", t_ns,
        View(rosmsg::EncodePoseStamped({{t_ns, "world"}, pose})));
}

void RunRecorder::Decision(Timestamp t_ns, const nlohmann::json& decision) {
  Write(kDecisionTopic, kJson, t_ns, decision.dump());
}

void RunRecorder::Close() { writer_.Close(); }

}  // namespace mapless::recording
