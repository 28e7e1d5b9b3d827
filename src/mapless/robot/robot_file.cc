#include "mapless/robot/robot_file.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <iterator>

#include "mapless/core/check.h"
#include "mapless/io/atomic_file.h"
#include "mapless/io/limits.h"
#include "mapless/io/yaml_reader.h"

namespace mapless::robot {

const char* CameraMountName(CameraMount m) {
  switch (m) {
    case CameraMount::kUpright:
      return "upright";
    case CameraMount::kRotated180:
      return "rotated_180";
    case CameraMount::kMirrored:
      return "mirrored";
    case CameraMount::kFlippedVertically:
      return "flipped_vertically";
  }
  return "?";
}

namespace {

bool ValidTopic(const std::string& t) {
  if (t.empty() || t.size() > 256) return false;
  for (std::size_t i = 0; i < t.size(); ++i) {
    const char c = t[i];
    const bool ok = std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '/';
    if (!ok) return false;
    if (c == '/' && i + 1 < t.size() && t[i + 1] == '/') return false;
  }
  const std::size_t first = t[0] == '/' ? 1 : 0;
  if (first >= t.size()) return false;  // "/" alone
  return std::isdigit(static_cast<unsigned char>(t[first])) == 0 && t.back() != '/';
}

void CheckTopic(const io::YamlMap& map, const std::string& key, const std::string& value,
                bool may_be_empty) {
  if (value.empty() && may_be_empty) return;
  if (!ValidTopic(value))
    map.Fail(key, "'" + value +
                      "' is not a ROS topic name (letters, digits, '_' and '/', not starting "
                      "with a digit, no '//', no trailing '/')");
}

double Positive(const io::YamlMap& map, const std::string& key, double fallback, double hi) {
  const double v = map.GetDouble(key, fallback);
  if (!std::isfinite(v) || v <= 0.0 || v > hi)
    map.Fail(key, "must be in (0, " + std::to_string(hi) + "]");
  return v;
}

}  // namespace

std::string RobotFile::Resolve(const std::string& topic) const {
  if (topic.empty() || topic[0] == '/') return topic;
  if (ns.empty() || ns == "/") return "/" + topic;
  return ns + "/" + topic;
}

LoopOptions RobotFile::Loop() const {
  LoopOptions o;
  o.max_speed_mps = max_speed_mps;
  o.max_turn_rate_radps = max_turn_rate_radps;
  o.max_frame_age_s = max_frame_age_s;
  o.give_up_without_frames_s = give_up_without_frames_s;
  o.max_blocked_s = max_blocked_s;
  return o;
}

void RobotFile::Validate() const {
  Loop().Validate();
  obstacle.Validate();
}

namespace {

// The section `topics`: each topic valid, and each role's topic another.
void ParseTopics(const io::YamlMap& t, RobotFile* r) {
  t.CheckKnownKeys(
      {"image", "compressed_image", "odometry", "cmd_vel", "status", "debug_image", "estop"});
  auto get = [&](const char* key, std::string* field, bool may_be_empty) {
    *field = t.GetString(key, *field);
    CheckTopic(t, key, *field, may_be_empty);
  };
  get("image", &r->topics.image, false);
  get("compressed_image", &r->topics.compressed_image, true);
  get("odometry", &r->topics.odometry, true);
  get("cmd_vel", &r->topics.cmd_vel, false);
  get("status", &r->topics.status, false);
  get("debug_image", &r->topics.debug_image, true);
  get("estop", &r->topics.estop, true);
  // One topic for two roles (cmd_vel on the camera topic, say) would feed mapless its own
  // messages or drive the robot with them: every topic it uses must be another.
  const std::pair<const char*, const std::string*> roles[] = {
      {"image", &r->topics.image},       {"compressed_image", &r->topics.compressed_image},
      {"odometry", &r->topics.odometry}, {"cmd_vel", &r->topics.cmd_vel},
      {"status", &r->topics.status},     {"debug_image", &r->topics.debug_image},
      {"estop", &r->topics.estop}};
  for (std::size_t i = 0; i < std::size(roles); ++i) {
    for (std::size_t j = 0; j < i; ++j) {
      if (roles[i].second->empty() || r->Resolve(*roles[i].second) != r->Resolve(*roles[j].second))
        continue;
      t.Fail(roles[i].first, "'" + *roles[i].second + "' is also the " + roles[j].first +
                                 " topic; each role needs a topic of its own");
    }
  }
}

// The section `obstacles`: the obstacle watch (navigation/obstacle_watch.h).
void ParseObstacles(const io::YamlMap& o, RobotFile* r) {
  o.CheckKnownKeys({"on_obstacle", "region_top", "region_far_m", "region_width",
                    "region_half_width_m", "horizon", "baseline_m", "min_blocked_fraction",
                    "max_unchecked_m", "creep_m", "creep_speed_mps", "hidden_drop",
                    "hidden_min_reference"});
  const std::string on = o.GetString("on_obstacle", "stop");
  if (on != "stop" && on != "avoid" && on != "off")
    o.Fail("on_obstacle", "'" + on + "' is not stop, avoid or off");
  r->obstacle.enabled = on != "off";
  r->obstacle.avoid = on == "avoid";
  const auto fraction = [&](const std::string& key, double fallback, double lo, double hi) {
    const double v = o.GetDouble(key, fallback);
    if (!std::isfinite(v) || v < lo || v > hi)
      o.Fail(key, "must be in [" + std::to_string(lo).substr(0, 4) + ", " +
                      std::to_string(hi).substr(0, 4) + "]");
    return v;
  };
  r->obstacle.region_top = fraction("region_top", r->obstacle.region_top, 0.0, 0.95);
  r->obstacle.fit_top = std::min(r->obstacle.fit_top, r->obstacle.region_top);
  r->obstacle.region_far_m = fraction("region_far_m", r->obstacle.region_far_m, 0.2, 50.0);
  r->obstacle.region_width = fraction("region_width", r->obstacle.region_width, 0.05, 1.0);
  r->obstacle.region_half_width_m =
      fraction("region_half_width_m", r->obstacle.region_half_width_m, 0.05, 2.0);
  r->obstacle.horizon = fraction("horizon", r->obstacle.horizon, 0.0, 0.94);
  if (r->obstacle.horizon >= r->obstacle.region_top)
    o.Fail("horizon", "must be above region_top (a smaller fraction)");
  r->obstacle.baseline_m = fraction("baseline_m", r->obstacle.baseline_m, 0.01, 1.0);
  r->obstacle_baseline_given = o.Has("baseline_m");
  r->obstacle.min_blocked_fraction =
      fraction("min_blocked_fraction", r->obstacle.min_blocked_fraction, 0.01, 0.99);
  r->obstacle.max_unchecked_m = fraction("max_unchecked_m", r->obstacle.max_unchecked_m, 0.0, 10.0);
  r->obstacle_max_unchecked_given = o.Has("max_unchecked_m");
  r->obstacle.creep_m = fraction("creep_m", r->obstacle.creep_m, 0.0, 2.0);
  r->obstacle.creep_speed_mps = fraction("creep_speed_mps", r->obstacle.creep_speed_mps, 0.01, 0.5);
  r->obstacle.hidden_drop = fraction("hidden_drop", r->obstacle.hidden_drop, 0.0, 0.95);
  r->obstacle.hidden_min_reference =
      fraction("hidden_min_reference", r->obstacle.hidden_min_reference, 0.05, 1.0);
}

}  // namespace

RobotFile ParseRobotFile(const std::string& text, const std::string& name) {
  return io::WithYamlErrors(name, [&] {
    const io::YamlMap map = io::YamlMap::LoadString(text, name);
    map.CheckKnownKeys({"middleware", "name", "namespace", "node_name", "topics", "limits",
                        "obstacles", "camera", "safety", "use_sim_time", "threads"});
    RobotFile r;
    r.source = name;
    r.middleware = map.GetString("middleware", r.middleware);
    if (std::find(std::begin(kMiddlewareNames), std::end(kMiddlewareNames), r.middleware) ==
        std::end(kMiddlewareNames)) {
      std::string known;
      for (const char* n : kMiddlewareNames) known += (known.empty() ? "" : ", ") + std::string(n);
      map.Fail("middleware", "'" + r.middleware + "' is not one of " + known);
    }
    r.name = map.GetString("name", r.name);
    r.ns = map.GetString("namespace", "");
    if (!r.ns.empty()) {
      if (r.ns[0] != '/') r.ns = "/" + r.ns;
      if (r.ns != "/") CheckTopic(map, "namespace", r.ns, false);
    }
    r.node_name = map.GetString("node_name", r.node_name);
    if (!ValidTopic(r.node_name) || r.node_name.find('/') != std::string::npos)
      map.Fail("node_name", "'" + r.node_name + "' is not a ROS node name");
    if (map.Has("topics")) ParseTopics(map.GetMap("topics"), &r);
    if (map.Has("limits")) {
      const io::YamlMap l = map.GetMap("limits");
      l.CheckKnownKeys({"max_speed_mps", "max_turn_rate_radps"});
      r.max_speed_mps = Positive(l, "max_speed_mps", r.max_speed_mps, 5.0);
      r.max_turn_rate_radps = Positive(l, "max_turn_rate_radps", r.max_turn_rate_radps, 10.0);
    }
    if (map.Has("camera")) {
      const io::YamlMap c = map.GetMap("camera");
      c.CheckKnownKeys({"mount"});
      const std::string mount = c.GetString("mount", "upright");
      bool found = false;
      for (CameraMount m : {CameraMount::kUpright, CameraMount::kRotated180, CameraMount::kMirrored,
                            CameraMount::kFlippedVertically}) {
        if (mount == CameraMountName(m)) {
          r.mount = m;
          found = true;
        }
      }
      if (!found)
        c.Fail("mount",
               "'" + mount + "' is not one of upright, rotated_180, mirrored, flipped_vertically");
    }
    if (map.Has("safety")) {
      const io::YamlMap s = map.GetMap("safety");
      s.CheckKnownKeys({"camera_timeout_s", "max_frame_age_s", "give_up_without_frames_s",
                        "connect_timeout_s", "max_blocked_s"});
      r.camera_timeout_s = Positive(s, "camera_timeout_s", r.camera_timeout_s, 10.0);
      r.max_frame_age_s = Positive(s, "max_frame_age_s", r.max_frame_age_s, 60.0);
      r.give_up_without_frames_s =
          s.GetDouble("give_up_without_frames_s", r.give_up_without_frames_s);
      if (!std::isfinite(r.give_up_without_frames_s) || r.give_up_without_frames_s < 0.0 ||
          r.give_up_without_frames_s > 3600.0)
        s.Fail("give_up_without_frames_s", "must be in [0, 3600] (0: wait for ever)");
      r.connect_timeout_s = Positive(s, "connect_timeout_s", r.connect_timeout_s, 600.0);
      r.max_blocked_s = s.GetDouble("max_blocked_s", r.max_blocked_s);
      if (!std::isfinite(r.max_blocked_s) || r.max_blocked_s < 0.0 || r.max_blocked_s > 86400.0)
        s.Fail("max_blocked_s", "must be in [0, 86400] (0: wait for ever)");
    }
    if (map.Has("obstacles")) ParseObstacles(map.GetMap("obstacles"), &r);
    r.use_sim_time = map.GetBool("use_sim_time", false);
    r.threads = map.GetInt("threads", r.threads);
    if (r.threads != 1 && r.threads != 2) map.Fail("threads", "must be 1 or 2");
    r.Validate();
    return r;
  });
}

RobotFile LoadRobotFile(const std::string& path) {
  RobotFile r = ParseRobotFile(io::ReadFile(path, io::kMaxYamlFileBytes), path);
  return r;
}

}  // namespace mapless::robot
