#include "mapless/live/feed.h"

#include <cmath>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "mapless/io/lazy_libraries.h"
#include "mapless/robot/methods.h"
#include "mapless/robot/status.h"
#include "mapless/rosmsg/definitions.h"
#include "mapless/rosmsg/messages.h"

namespace mapless::live {
namespace {

// The JSON Schemas of the channels in JSON (Foxglove recognises the foxglove.* names and draws
// them in its 3D panel; the schemas name the fields for its Plot panel's completion).
constexpr const char* kTimeSchema =
    R"({"type":"object","properties":{"sec":{"type":"integer"},"nsec":{"type":"integer"}}})";
constexpr const char* kVector3Schema =
    R"({"type":"object","properties":{"x":{"type":"number"},"y":{"type":"number"},"z":{"type":"number"}}})";
constexpr const char* kQuaternionSchema =
    R"({"type":"object","properties":{"x":{"type":"number"},"y":{"type":"number"},"z":{"type":"number"},"w":{"type":"number"}}})";

std::string DecisionSchema() {
  nlohmann::json s = {
      {"title", "mapless.Decision"},
      {"description", "One decision of a mapless method (docs/live_view.md): robot/status.h"},
      {"type", "object"},
      {"properties",
       {{"t_s", {{"type", "number"}}},
        {"method", {{"type", "string"}}},
        {"frame", {{"type", "integer"}}},
        {"state", {{"type", "string"}, {"enum", {"driving", "stopped", "finished", "failed"}}}},
        {"status", {{"type", "string"}}},
        {"reason", {{"type", "string"}}},
        {"v_mps", {{"type", "number"}}},
        {"omega_radps", {{"type", "number"}}}}},
      {"required", {"t_s", "method", "state"}},
      {"additionalProperties", true}};
  return s.dump();
}

std::string FrameTransformsSchema() {
  const nlohmann::json time = nlohmann::json::parse(kTimeSchema);
  nlohmann::json t = {{"type", "object"},
                      {"properties",
                       {{"timestamp", time},
                        {"parent_frame_id", {{"type", "string"}}},
                        {"child_frame_id", {{"type", "string"}}},
                        {"translation", nlohmann::json::parse(kVector3Schema)},
                        {"rotation", nlohmann::json::parse(kQuaternionSchema)}}}};
  nlohmann::json s = {{"title", "foxglove.FrameTransforms"},
                      {"type", "object"},
                      {"properties", {{"transforms", {{"type", "array"}, {"items", t}}}}}};
  return s.dump();
}

std::string PosesInFrameSchema() {
  nlohmann::json pose = {{"type", "object"},
                         {"properties",
                          {{"position", nlohmann::json::parse(kVector3Schema)},
                           {"orientation", nlohmann::json::parse(kQuaternionSchema)}}}};
  nlohmann::json s = {{"title", "foxglove.PosesInFrame"},
                      {"type", "object"},
                      {"properties",
                       {{"timestamp", nlohmann::json::parse(kTimeSchema)},
                        {"frame_id", {{"type", "string"}}},
                        {"poses", {{"type", "array"}, {"items", pose}}}}}};
  return s.dump();
}

std::string BeliefSchema() {
  nlohmann::json s = {
      {"title", "mapless.Belief"},
      {"description", "The Markov localization's belief over the route images (follow)"},
      {"type", "object"},
      {"properties",
       {{"timestamp", nlohmann::json::parse(kTimeSchema)},
        {"index", {{"type", "integer"}}},
        {"belief", {{"type", "array"}, {"items", {{"type", "number"}}}}}}}};
  return s.dump();
}

Channel Ros(std::uint32_t id, const char* topic, const char* type) {
  return {id, topic, "cdr", type, rosmsg::ConcatenatedDefinition(type), "ros2msg"};
}
Channel Json(std::uint32_t id, const char* topic, const char* name, std::string schema) {
  return {id, topic, "json", name, std::move(schema), "jsonschema"};
}

nlohmann::json Time(Timestamp t_ns) {
  const std::int64_t t = std::max<std::int64_t>(t_ns, 0);
  return {{"sec", t / 1000000000}, {"nsec", t % 1000000000}};
}

nlohmann::json PoseJson(const Pose2& p) {
  return {{"position", {{"x", p.x_m}, {"y", p.y_m}, {"z", 0.0}}},
          {"orientation",
           {{"x", 0.0},
            {"y", 0.0},
            {"z", std::sin(p.theta_rad / 2)},
            {"w", std::cos(p.theta_rad / 2)}}}};
}

std::string CompressedImage(Timestamp t_ns, const char* frame_id, const cv::Mat& image,
                            int quality) {
  std::vector<uchar> jpeg;
  io::lazy::ImEncode(".jpg", image, &jpeg, {cv::IMWRITE_JPEG_QUALITY, quality});
  rosmsg::CompressedImageFields m;
  m.header = {t_ns, frame_id};
  m.format = "jpeg";
  m.data = std::string_view(reinterpret_cast<const char*>(jpeg.data()), jpeg.size());
  const std::vector<std::uint8_t> bytes = rosmsg::EncodeCompressedImage(m);
  return std::string(bytes.begin(), bytes.end());
}

std::string Bytes(const std::vector<std::uint8_t>& v) { return std::string(v.begin(), v.end()); }

}  // namespace

bool IsImageChannel(std::uint32_t channel_id) {
  return channel_id == kCameraChannel || channel_id == kDebugChannel;
}

std::vector<Channel> RunChannels(const std::string& method, bool has_route) {
  std::vector<Channel> c = {
      Ros(kCameraChannel, "/camera/image_raw/compressed", "sensor_msgs/msg/CompressedImage"),
      Ros(kDebugChannel, "/mapless/debug_image/compressed", "sensor_msgs/msg/CompressedImage"),
      Json(kDecisionChannel, "/mapless/decision", "mapless.Decision", DecisionSchema()),
      Json(kTfChannel, "/tf", "foxglove.FrameTransforms", FrameTransformsSchema()),
      Json(kPathChannel, "/mapless/path", "foxglove.PosesInFrame", PosesInFrameSchema()),
  };
  if (has_route)
    c.push_back(
        Json(kRouteChannel, "/mapless/route", "foxglove.PosesInFrame", PosesInFrameSchema()));
  c.push_back(Ros(kOdomChannel, "/odom", "nav_msgs/msg/Odometry"));
  c.push_back(Ros(kCmdVelChannel, "/cmd_vel", "geometry_msgs/msg/Twist"));
  if (method == "follow")
    c.push_back(Json(kBeliefChannel, "/mapless/belief", "mapless.Belief", BeliefSchema()));
  return c;
}

Feed::Feed(std::vector<Pose2> route, FeedOptions options)
    : route_(std::move(route)), options_(options) {}

void Feed::AddToPath(const Pose2& pose) {
  if (!path_.empty()) {
    const Pose2& last = path_.back();
    if (std::hypot(pose.x_m - last.x_m, pose.y_m - last.y_m) < options_.path_step_m &&
        std::abs(WrapAngle(pose.theta_rad - last.theta_rad)) < options_.path_step_rad)
      return;
  }
  path_.push_back(pose);
  if (path_.size() > options_.max_path_poses) {
    std::vector<Pose2> kept;
    for (std::size_t i = 0; i < path_.size(); i += 2) kept.push_back(path_[i]);
    kept.push_back(path_.back());
    path_ = std::move(kept);
  }
}

std::string Feed::PosesMessage(const std::vector<Pose2>& poses, Timestamp t_ns) const {
  nlohmann::json j = {{"timestamp", Time(t_ns)}, {"frame_id", "odom"}};
  j["poses"] = nlohmann::json::array();
  for (const Pose2& p : poses) j["poses"].push_back(PoseJson(p));
  return j.dump();
}

std::vector<Outgoing> Feed::Latched(Timestamp t_ns) const {
  std::vector<Outgoing> out;
  if (!path_.empty()) out.push_back({kPathChannel, PosesMessage(path_, t_ns)});
  if (!route_.empty()) out.push_back({kRouteChannel, PosesMessage(route_, t_ns)});
  return out;
}

std::vector<Outgoing> Feed::Messages(const FrameView& f) {
  const robot::Observation& obs = f.observation;
  const Timestamp t = obs.t_ns;
  std::vector<Outgoing> out;
  const char* method = f.method.c_str();
  if (!f.stop_reason.empty()) {
    nlohmann::json j = robot::StopJson(method, t, f.stop_reason);
    out.push_back(
        {kDecisionChannel, j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace)});
    out.push_back({kCmdVelChannel, Bytes(rosmsg::EncodeTwist(Twist2{}))});
    if (!path_.empty()) out.push_back({kPathChannel, PosesMessage(path_, t)});
    return out;
  }
  if (!obs.image.empty()) {
    out.push_back({kCameraChannel, CompressedImage(t, "camera", obs.image, options_.jpeg_quality)});
    out.push_back({kDebugChannel, CompressedImage(t, "camera", robot::DebugImage(obs, f.decision),
                                                  options_.jpeg_quality)});
  }
  nlohmann::json j = robot::StatusJson(method, f.frame, obs, f.decision);
  j["frame"] = f.frame;
  if (f.truth) {
    j["x_m"] = f.truth->x_m;
    j["y_m"] = f.truth->y_m;
    j["theta_rad"] = f.truth->theta_rad;
  }
  out.push_back(
      {kDecisionChannel, j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace)});
  const std::optional<Pose2> where = obs.odometry ? obs.odometry : f.truth;
  if (where) {
    nlohmann::json tf = {{"timestamp", Time(t)},
                         {"parent_frame_id", "odom"},
                         {"child_frame_id", "base_link"},
                         {"translation", {{"x", where->x_m}, {"y", where->y_m}, {"z", 0.0}}},
                         {"rotation", PoseJson(*where)["orientation"]}};
    out.push_back({kTfChannel, nlohmann::json{{"transforms", {tf}}}.dump()});
    AddToPath(*where);
    if (frames_ % options_.path_every_frames == 0)
      out.push_back({kPathChannel, PosesMessage(path_, t)});
  }
  if (frames_ == 0 && !route_.empty()) out.push_back({kRouteChannel, PosesMessage(route_, t)});
  if (obs.odometry) {
    rosmsg::OdometryFields odom;
    odom.header = {t, "odom"};
    odom.child_frame_id = "base_link";
    odom.pose = *obs.odometry;
    odom.twist = f.command;
    out.push_back({kOdomChannel, Bytes(rosmsg::EncodeOdometry(odom))});
  }
  out.push_back({kCmdVelChannel, Bytes(rosmsg::EncodeTwist(f.command))});
  if (const auto* d = f.decision.DetailAs<robot::FollowerDetail>()) {
    if (!d->step.belief.empty()) {
      nlohmann::json b = {{"timestamp", Time(t)}, {"index", d->step.index}};
      b["belief"] = d->step.belief;
      out.push_back({kBeliefChannel, b.dump()});
    }
  }
  ++frames_;
  return out;
}

}  // namespace mapless::live
