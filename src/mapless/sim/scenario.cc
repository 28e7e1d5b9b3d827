#include "mapless/sim/scenario.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string_view>

#include "mapless/core/check.h"
#include "mapless/io/atomic_file.h"
#include "mapless/io/limits.h"
#include "mapless/io/yaml_reader.h"
#include "mapless/sim/builtin_scenarios.h"
#include "mapless/sim/sessions.h"
#include "mapless/sim/world_yaml.h"

namespace mapless::sim {
namespace {

using io::YamlMap;
using yaml::MixSeed;
using yaml::ParseObject;
using yaml::ParseWorld;
using yaml::ParseWorldChange;
using yaml::PoseDeg;
using yaml::RequirePositive;
using yaml::Vec2;

ImageEffects ParseEffects(const YamlMap& e) {
  e.CheckKnownKeys({"noise_sigma", "invert_fraction", "gain", "bias", "blur_sigma_px"});
  ImageEffects effects;
  effects.noise_sigma = e.GetDouble("noise_sigma", 0.0);
  effects.invert_fraction = e.GetDouble("invert_fraction", 0.0);
  effects.gain = e.GetDouble("gain", 1.0);
  effects.bias = e.GetDouble("bias", 0.0);
  effects.blur_sigma_px = e.GetDouble("blur_sigma_px", 0.0);
  return effects;
}

CameraSpec ParseCamera(const YamlMap& m) {
  m.CheckKnownKeys({"width", "height", "hfov_deg", "height_m", "pitch_deg", "forward_m",
                    "lateral_m", "rate_hz", "effects"});
  CameraSpec c;
  const int width = m.GetInt("width", 320);
  const int height = m.GetInt("height", 240);
  const double hfov = m.GetDouble("hfov_deg", 60.0);
  if (!(hfov > 1.0 && hfov < 170.0)) m.Fail("hfov_deg", "must be in (1, 170)");
  if (width < 16 || width > 4096) m.Fail("width", "must be in [16, 4096]");
  if (height < 16 || height > 4096) m.Fail("height", "must be in [16, 4096]");
  c.model = CameraModel::FromFov(width, height, DegToRad(hfov));
  c.mount.height_m = m.GetDouble("height_m", c.mount.height_m);
  c.mount.pitch_rad = DegToRad(m.GetDouble("pitch_deg", 0.0));
  c.mount.forward_m = m.GetDouble("forward_m", 0.0);
  c.mount.lateral_m = m.GetDouble("lateral_m", 0.0);
  c.rate_hz = m.GetDouble("rate_hz", c.rate_hz);
  if (m.Has("effects")) c.effects = ParseEffects(m.GetMap("effects"));
  try {
    c.Validate();
  } catch (const InputError& e) {
    m.Fail("", e.what());
  }
  return c;
}

RobotOptions ParseRobot(const YamlMap& m) {
  m.CheckKnownKeys({"radius_m", "max_v_mps", "max_omega_radps", "max_accel_mps2",
                    "max_alpha_radps2", "motion_noise_v_frac", "motion_noise_omega_frac",
                    "odom_scale_error", "odom_noise_v_mps", "odom_noise_omega_radps"});
  RobotOptions r;
  r.radius_m = m.GetDouble("radius_m", r.radius_m);
  r.max_v_mps = m.GetDouble("max_v_mps", r.max_v_mps);
  r.max_omega_radps = m.GetDouble("max_omega_radps", r.max_omega_radps);
  r.max_accel_mps2 = m.GetDouble("max_accel_mps2", r.max_accel_mps2);
  r.max_alpha_radps2 = m.GetDouble("max_alpha_radps2", r.max_alpha_radps2);
  r.motion_noise_v_frac = m.GetDouble("motion_noise_v_frac", r.motion_noise_v_frac);
  r.motion_noise_omega_frac = m.GetDouble("motion_noise_omega_frac", r.motion_noise_omega_frac);
  r.odom_scale_error = m.GetDouble("odom_scale_error", r.odom_scale_error);
  r.odom_noise_v_mps = m.GetDouble("odom_noise_v_mps", r.odom_noise_v_mps);
  r.odom_noise_omega_radps = m.GetDouble("odom_noise_omega_radps", r.odom_noise_omega_radps);
  try {
    r.Validate();
  } catch (const InputError& e) {
    m.Fail("", e.what());
  }
  return r;
}

std::vector<PathStep> ParsePath(const YamlMap& teach) {
  std::vector<PathStep> path;
  const std::vector<YamlMap> items = teach.GetList("path");
  if (items.size() > kMaxPathSteps) {
    teach.Fail("path", std::to_string(items.size()) + " steps; the limit is " +
                           std::to_string(kMaxPathSteps));
  }
  for (const YamlMap& item : items) {
    PathStep step;
    if (item.node().IsSequence()) {
      const std::size_t n = item.node().size();
      if (n != 2 && n != 3) item.Fail("", "expected [x, y] or [x, y, speed_mps]");
      std::vector<double> v;
      for (const auto& e : item.node()) {
        double d = 0.0;
        if (!e.IsScalar() || !YAML::convert<double>::decode(e, d) || !std::isfinite(d)) {
          item.Fail("", "expected numbers");
        }
        v.push_back(d);
      }
      step.kind = PathStep::Kind::kGoTo;
      step.target = Eigen::Vector2d(v[0], v[1]);
      step.speed_mps = n == 3 ? v[2] : 0.0;
      if (n == 3 && !(step.speed_mps > 0.0)) item.Fail("", "speed_mps must be > 0");
    } else if (item.node().IsMap()) {
      item.CheckKnownKeys({"rotate_deg"});
      step.kind = PathStep::Kind::kRotate;
      step.rotate_rad = DegToRad(item.GetDouble("rotate_deg"));
    } else {
      item.Fail("", "expected [x, y], [x, y, speed_mps] or {rotate_deg: angle}");
    }
    path.push_back(step);
  }
  if (path.empty()) teach.Fail("path", "the taught path needs at least one step");
  return path;
}

}  // namespace

void CameraSpec::Validate() const {
  model.Validate();
  mount.Validate();
  effects.Validate();
  MAPLESS_CHECK(rate_hz >= 1.0 && rate_hz <= 200.0,
                "CameraSpec.rate_hz = " << rate_hz << "; must be in [1, 200]");
}

void Scenario::Validate() const {
  world.Validate();
  camera.Validate();
  robot.Validate();
  const auto speed_ok = [](double v) {
    return std::isfinite(v) && v >= kMinPathSpeedMps && v <= kMaxPathSpeedMps;
  };
  MAPLESS_CHECK(speed_ok(teach_speed_mps),
                "Scenario.teach.speed_mps = " << teach_speed_mps << "; must be in ["
                                              << kMinPathSpeedMps << ", " << kMaxPathSpeedMps
                                              << "]");
  MAPLESS_CHECK(!teach_path.empty(), "Scenario.teach.path is empty");
  MAPLESS_CHECK(
      teach_path.size() <= kMaxPathSteps,
      "Scenario.teach.path: " << teach_path.size() << " steps; the limit is " << kMaxPathSteps);
  const auto where_ok = [](double x, double y) {
    return std::isfinite(x) && std::isfinite(y) && std::abs(x) <= kMaxWorldCoordinateM &&
           std::abs(y) <= kMaxWorldCoordinateM;
  };
  MAPLESS_CHECK(where_ok(teach_start.x_m, teach_start.y_m) && std::isfinite(teach_start.theta_rad),
                "Scenario.teach.start: beyond " << kMaxWorldCoordinateM << " m from the origin");
  MAPLESS_CHECK(
      where_ok(repeat_start.x_m, repeat_start.y_m) && std::isfinite(repeat_start.theta_rad),
      "Scenario.repeat.start: beyond " << kMaxWorldCoordinateM << " m from the origin");
  for (std::size_t i = 0; i < teach_path.size(); ++i) {
    const PathStep& step = teach_path[i];
    MAPLESS_CHECK(where_ok(step.target.x(), step.target.y()),
                  "Scenario.teach.path[" << i << "]: beyond " << kMaxWorldCoordinateM
                                         << " m from the origin");
    MAPLESS_CHECK(step.speed_mps == 0.0 || speed_ok(step.speed_mps),
                  "Scenario.teach.path[" << i << "]: speed " << step.speed_mps
                                         << " m/s; must be in [" << kMinPathSpeedMps << ", "
                                         << kMaxPathSpeedMps << "]");
    MAPLESS_CHECK(std::isfinite(step.rotate_rad) && std::abs(step.rotate_rad) <= kMaxRotateRad,
                  "Scenario.teach.path[" << i << "]: rotation of " << RadToDeg(step.rotate_rad)
                                         << " degrees; at most " << RadToDeg(kMaxRotateRad));
  }
  MAPLESS_CHECK(PathLength() <= kMaxPathLengthM, "Scenario.teach.path is "
                                                     << PathLength() << " m long; the limit is "
                                                     << kMaxPathLengthM << " m");
  MAPLESS_CHECK(
      destinations.size() <= kMaxDestinations,
      "Scenario.destinations: " << destinations.size() << "; the limit is " << kMaxDestinations);
  for (std::size_t i = 0; i < destinations.size(); ++i) {
    MAPLESS_CHECK(where_ok(destinations[i].x(), destinations[i].y()),
                  "Scenario.destinations[" << i << "]: beyond " << kMaxWorldCoordinateM
                                           << " m from the origin");
  }
}

Eigen::Vector4d ScenarioBounds(const Scenario& scenario, double margin_m) {
  Eigen::Vector4d b = FootprintBounds(scenario.world);
  const auto add = [&](double x, double y) {
    b[0] = std::min(b[0], x);
    b[1] = std::min(b[1], y);
    b[2] = std::max(b[2], x);
    b[3] = std::max(b[3], y);
  };
  add(scenario.teach_start.x_m, scenario.teach_start.y_m);
  add(scenario.repeat_start.x_m, scenario.repeat_start.y_m);
  for (const PathStep& step : scenario.teach_path) {
    if (step.kind == PathStep::Kind::kGoTo) add(step.target.x(), step.target.y());
  }
  for (const Eigen::Vector2d& d : scenario.destinations) add(d.x(), d.y());
  return b + Eigen::Vector4d(-margin_m, -margin_m, margin_m, margin_m);
}

double Scenario::PathLength() const {
  double length = 0.0;
  Eigen::Vector2d at(teach_start.x_m, teach_start.y_m);
  for (const PathStep& s : teach_path) {
    if (s.kind != PathStep::Kind::kGoTo) continue;
    length += (s.target - at).norm();
    at = s.target;
  }
  return length;
}

static Scenario ParseScenarioUnchecked(const std::string& yaml_text, const std::string& source,
                                       const std::string& base_dir) {
  const YamlMap root = YamlMap::LoadString(yaml_text, source);
  root.CheckKnownKeys({"name", "description", "paper", "seed", "world", "camera", "robot", "teach",
                       "repeat", "destinations", "sessions", "labels"});
  Scenario s;
  s.source = source;
  s.name = root.GetString("name", std::filesystem::path(source).stem().string());
  s.description = root.GetString("description", "");
  s.seed = static_cast<std::uint64_t>(root.GetInt("seed", 1));
  if (root.Has("labels")) {
    const YamlMap labels = root.GetMap("labels");
    for (const std::string& key : labels.Keys()) s.labels[key] = labels.GetString(key);
  }
  if (root.Has("world") && root.node()["world"].IsScalar()) {
    // A world in its own file, relative to this scenario.
    std::filesystem::path wf(root.GetString("world"));
    if (!wf.is_absolute() && !base_dir.empty()) wf = std::filesystem::path(base_dir) / wf;
    const YamlMap wm = YamlMap::LoadFile(wf.string());
    s.world = ParseWorld(wm, s.seed, wf.parent_path().string());
  } else {
    s.world = ParseWorld(root.GetMap("world"), s.seed, base_dir);
  }
  if (root.Has("camera")) s.camera = ParseCamera(root.GetMap("camera"));
  if (root.Has("robot")) s.robot = ParseRobot(root.GetMap("robot"));
  const YamlMap teach = root.GetMap("teach");
  teach.CheckKnownKeys({"start", "speed_mps", "path"});
  s.teach_start = PoseDeg(teach, "start");
  s.teach_speed_mps = teach.GetDouble("speed_mps", s.teach_speed_mps);
  RequirePositive(teach, "speed_mps", s.teach_speed_mps);
  s.teach_path = ParsePath(teach);
  s.repeat_start = s.teach_start;
  if (root.Has("repeat")) {
    const YamlMap repeat = root.GetMap("repeat");
    repeat.CheckKnownKeys({"start", "variant", "effects"});
    if (repeat.Has("start")) s.repeat_start = PoseDeg(repeat, "start");
    if (repeat.Has("effects")) {
      CameraSpec camera = s.camera;
      camera.effects = ParseEffects(repeat.GetMap("effects"));
      try {
        camera.Validate();
      } catch (const InputError& e) {
        repeat.Fail("effects", e.what());
      }
      s.repeat_effects = camera.effects;
    }
    if (repeat.Has("variant")) {
      const YamlMap v = repeat.GetMap("variant");
      v.CheckKnownKeys({"remove", "move", "add", "leave_s"});
      if (v.Has("remove")) s.repeat_variant.remove = v.GetStrings("remove");
      if (v.Has("move")) {
        const YamlMap mv = v.GetMap("move");
        for (const std::string& tag : mv.Keys()) s.repeat_variant.move_m[tag] = Vec2(mv, tag);
      }
      if (v.Has("add")) {
        const auto objects = v.GetMapList("add");
        for (std::size_t i = 0; i < objects.size(); ++i) {
          ParseObject(objects[i], MixSeed(s.seed, 5000 + i), base_dir, &s.repeat_variant.add);
          if (s.repeat_variant.add.size() > kMaxWorldObjects)
            v.Fail("add", "more than " + std::to_string(kMaxWorldObjects) + " objects");
        }
      }
      if (v.Has("leave_s")) {
        const YamlMap l = v.GetMap("leave_s");
        for (const std::string& tag : l.Keys()) {
          const double t = l.GetDouble(tag);
          if (!(t >= 0.0 && t < 1e6)) l.Fail(tag, "must be in [0, 1e6) s");
          s.repeat_variant.leave_s[tag] = t;
        }
      }
      try {
        ApplyVariant(s.world, s.repeat_variant).Validate();
      } catch (const InputError& e) {
        v.Fail("", e.what());
      }
    }
  }
  if (root.Has("sessions")) s.sessions = ParseWorldChange(root.GetMap("sessions"), s.world);
  if (root.Has("destinations")) {
    for (const YamlMap& d : root.GetList("destinations")) {
      const std::vector<double> xy = d.AsDoubles(2);
      s.destinations.emplace_back(xy[0], xy[1]);
    }
  }
  try {
    s.Validate();
  } catch (const InputError& e) {
    throw InputError(source + ": " + e.what());
  }
  return s;
}

Scenario ParseScenario(const std::string& yaml_text, const std::string& source,
                       const std::string& base_dir) {
  return io::WithYamlErrors(source,
                            [&] { return ParseScenarioUnchecked(yaml_text, source, base_dir); });
}

std::vector<std::string> BuiltinScenarioNames() {
  std::vector<std::string> names;
  for (std::size_t i = 0; i < kBuiltinScenarioCount; ++i)
    names.emplace_back(kBuiltinScenarios[i].name);
  std::sort(names.begin(), names.end());
  return names;
}

std::string BuiltinScenarioText(const std::string& name) {
  for (std::size_t i = 0; i < kBuiltinScenarioCount; ++i) {
    if (name == kBuiltinScenarios[i].name) return std::string(kBuiltinScenarios[i].text);
  }
  return "";
}

Scenario LoadScenario(const std::string& name_or_path) {
  // NAME@S: session S of a changing world (sessions.h).
  const std::size_t at = name_or_path.rfind('@');
  if (at != std::string::npos && at + 1 < name_or_path.size() &&
      name_or_path.find_first_not_of("0123456789", at + 1) == std::string::npos) {
    const std::string digits = name_or_path.substr(at + 1);
    if (digits.size() > 4)
      throw InputError(name_or_path + ": session " + digits + " (at most 9999)");
    return SessionScenario(LoadScenario(name_or_path.substr(0, at)), std::stoi(digits));
  }
  const bool looks_like_path = name_or_path.find('/') != std::string::npos ||
                               std::filesystem::path(name_or_path).extension() == ".yaml" ||
                               std::filesystem::path(name_or_path).extension() == ".yml";
  if (!looks_like_path) {
    const std::string text = BuiltinScenarioText(name_or_path);
    if (text.empty()) {
      throw InputError("unknown scenario '" + name_or_path +
                       "' (not a built-in name; see `mapless sim list`, or give a .yaml path)");
    }
    return ParseScenario(text, "builtin:" + name_or_path, "");
  }
  const std::string text = io::ReadFile(name_or_path, io::kMaxYamlFileBytes);
  return ParseScenario(text, name_or_path,
                       std::filesystem::path(name_or_path).parent_path().string());
}

}  // namespace mapless::sim
