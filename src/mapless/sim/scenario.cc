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

namespace mapless::sim {
namespace {

using io::YamlMap;

std::uint64_t MixSeed(std::uint64_t a, std::uint64_t b) {
  std::uint64_t z = a * 0x9E3779B97F4A7C15ULL + b + 0x632BE59BD9B4E019ULL;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  return z ^ (z >> 31);
}

TextureSpec ParseTexture(const YamlMap& m, std::uint64_t default_seed,
                         const std::string& base_dir) {
  m.CheckKnownKeys({"type", "seed", "texel_m", "fit", "mean", "contrast", "size_px", "file"});
  TextureSpec t;
  try {
    t.type = ParseTextureType(m.GetString("type", "noise"));
  } catch (const InputError& e) {
    m.Fail("type", e.what());
  }
  t.seed = m.Has("seed") ? static_cast<std::uint64_t>(m.GetInt("seed")) : default_seed;
  t.texel_m = m.GetDouble("texel_m", t.texel_m);
  t.fit = m.GetBool("fit", t.type == TextureType::kPoster);
  t.mean = m.GetDouble("mean", t.mean);
  t.contrast = m.GetDouble("contrast", t.contrast);
  t.size_px = m.GetInt("size_px", t.size_px);
  if (m.Has("file")) {
    const std::filesystem::path f(m.GetString("file"));
    t.file = f.is_absolute() || base_dir.empty() ? f.string()
                                                 : (std::filesystem::path(base_dir) / f).string();
  }
  try {
    t.Validate();
  } catch (const InputError& e) {
    m.Fail("", e.what());
  }
  return t;
}

Eigen::Vector2d Vec2(const YamlMap& m, const std::string& key) {
  const auto v = m.GetDoubles(key, 2);
  return Eigen::Vector2d(v[0], v[1]);
}

Pose2 PoseDeg(const YamlMap& m, const std::string& key) {
  const auto v = m.GetDoubles(key, 3);
  return Pose2{v[0], v[1], WrapAngle(DegToRad(v[2]))};
}

void RequirePositive(const YamlMap& m, const std::string& key, double v) {
  if (!(v > 0.0)) m.Fail(key, "must be > 0, got " + std::to_string(v));
}

// Parses one entry of world.objects; `room` and multi-point walls expand to several objects, and
// `repeat` copies the object `count` times with a constant offset.
void ParseObject(const YamlMap& m, std::uint64_t seed, const std::string& base_dir,
                 std::vector<WorldObject>* out) {
  m.CheckKnownKeys({"type", "tag", "texture", "points", "min", "max", "center", "size_m",
                    "height_m", "radius_m", "yaw_deg", "facing_deg", "repeat", "appears_s",
                    "leaves_s"});
  const std::string type = m.GetString("type");
  WorldObject o;
  o.tag = m.GetString("tag", "");
  o.appears_s = m.GetDouble("appears_s", 0.0);
  if (!(o.appears_s >= 0.0 && o.appears_s < 1e6)) m.Fail("appears_s", "must be in [0, 1e6) s");
  if (m.Has("leaves_s")) {
    o.leaves_s = m.GetDouble("leaves_s");
    if (!(o.leaves_s > o.appears_s && o.leaves_s < 1e6))
      m.Fail("leaves_s", "must be after appears_s and below 1e6 s");
  }
  o.texture = m.Has("texture") ? ParseTexture(m.GetMap("texture"), seed, base_dir) : TextureSpec{};
  if (!m.Has("texture")) o.texture.seed = seed;
  std::vector<WorldObject> made;
  if (type == "wall" || type == "room") {
    o.kind = ObjectKind::kWall;
    o.height_m = m.GetDouble("height_m", 2.5);
    RequirePositive(m, "height_m", o.height_m);
    std::vector<Eigen::Vector2d> pts;
    if (type == "wall") {
      const auto list = m.GetList("points");
      if (list.size() < 2) m.Fail("points", "a wall needs at least 2 points");
      for (const auto& p : list) {
        const std::vector<double> xy = p.AsDoubles(2);
        pts.emplace_back(xy[0], xy[1]);
      }
    } else {
      const Eigen::Vector2d lo = Vec2(m, "min");
      const Eigen::Vector2d hi = Vec2(m, "max");
      if (!(hi.x() > lo.x() && hi.y() > lo.y()))
        m.Fail("max", "must be greater than min in x and y");
      pts = {lo, {hi.x(), lo.y()}, hi, {lo.x(), hi.y()}, lo};
    }
    for (std::size_t i = 0; i + 1 < pts.size(); ++i) {
      if ((pts[i + 1] - pts[i]).norm() < 1e-6) m.Fail("points", "consecutive points must differ");
      WorldObject w = o;
      w.a = pts[i];
      w.b = pts[i + 1];
      made.push_back(w);
    }
  } else if (type == "box") {
    o.kind = ObjectKind::kBox;
    o.center = Vec2(m, "center");
    const auto size = m.GetDoubles("size_m", 3);
    for (double s : size) RequirePositive(m, "size_m", s);
    o.size_m = Eigen::Vector2d(size[0], size[1]);
    o.height_m = size[2];
    o.yaw_rad = DegToRad(m.GetDouble("yaw_deg", 0.0));
    made.push_back(o);
  } else if (type == "cylinder") {
    o.kind = ObjectKind::kCylinder;
    o.center = Vec2(m, "center");
    o.radius_m = m.GetDouble("radius_m");
    o.height_m = m.GetDouble("height_m", 1.0);
    RequirePositive(m, "radius_m", o.radius_m);
    RequirePositive(m, "height_m", o.height_m);
    made.push_back(o);
  } else if (type == "poster") {
    o.kind = ObjectKind::kPoster;
    const auto c = m.GetDoubles("center", 3);
    o.center = Eigen::Vector2d(c[0], c[1]);
    o.z_m = c[2];
    o.size_m = Vec2(m, "size_m");
    RequirePositive(m, "size_m", std::min(o.size_m.x(), o.size_m.y()));
    o.yaw_rad = DegToRad(m.GetDouble("facing_deg", 0.0));
    if (!m.Has("texture")) {
      o.texture.type = TextureType::kPoster;
      o.texture.fit = true;
    }
    made.push_back(o);
  } else {
    m.Fail("type", "unknown object type '" + type + "' (known: wall, room, box, cylinder, poster)");
  }
  int count = 1;
  Eigen::Vector2d step = Eigen::Vector2d::Zero();
  if (m.Has("repeat")) {
    const YamlMap r = m.GetMap("repeat");
    r.CheckKnownKeys({"count", "step"});
    count = r.GetInt("count");
    if (count < 1 || count > 1000) r.Fail("count", "must be in [1, 1000]");
    step = Vec2(r, "step");
  }
  // Copies look alike only when the texture seed is given explicitly (visual aliasing on purpose);
  // otherwise each copy gets its own derived seed.
  const bool explicit_seed = m.Has("texture") && m.GetMap("texture").Has("seed");
  for (int k = 0; k < count; ++k) {
    for (WorldObject w : made) {
      const Eigen::Vector2d d = step * k;
      w.a += d;
      w.b += d;
      w.center += d;
      if (!explicit_seed && k > 0)
        w.texture.seed = MixSeed(w.texture.seed, static_cast<std::uint64_t>(k));
      out->push_back(w);
    }
  }
}

World ParseWorld(const YamlMap& m, std::uint64_t seed, const std::string& base_dir) {
  m.CheckKnownKeys({"ground", "ceiling", "sky", "objects"});
  World w;
  w.ground = m.Has("ground") ? ParseTexture(m.GetMap("ground"), MixSeed(seed, 1), base_dir)
                             : TextureSpec{};
  if (!m.Has("ground")) w.ground.seed = MixSeed(seed, 1);
  if (m.Has("ceiling")) {
    const YamlMap c = m.GetMap("ceiling");
    c.CheckKnownKeys({"height_m", "texture"});
    w.ceiling_height_m = c.GetDouble("height_m", w.ceiling_height_m);
    RequirePositive(c, "height_m", w.ceiling_height_m);
    w.ceiling = c.Has("texture") ? ParseTexture(c.GetMap("texture"), MixSeed(seed, 2), base_dir)
                                 : TextureSpec{};
  }
  if (m.Has("sky")) {
    const YamlMap s = m.GetMap("sky");
    s.CheckKnownKeys({"top", "horizon"});
    w.sky_top = s.GetDouble("top", w.sky_top);
    w.sky_horizon = s.GetDouble("horizon", w.sky_horizon);
  }
  if (m.Has("objects")) {
    const auto objects = m.GetMapList("objects");
    for (std::size_t i = 0; i < objects.size(); ++i) {
      ParseObject(objects[i], MixSeed(seed, 100 + i), base_dir, &w.objects);
      // Checked as the list grows: YAML aliases can repeat one entry a million times in a few
      // bytes, and each entry can expand to a thousand objects.
      if (w.objects.size() > kMaxWorldObjects) {
        m.Fail("objects", "more than " + std::to_string(kMaxWorldObjects) +
                              " objects (after rooms and repeats) by entry " + std::to_string(i));
      }
    }
  }
  return w;
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
  if (m.Has("effects")) {
    const YamlMap e = m.GetMap("effects");
    e.CheckKnownKeys({"noise_sigma", "invert_fraction", "gain", "bias", "blur_sigma_px"});
    c.effects.noise_sigma = e.GetDouble("noise_sigma", 0.0);
    c.effects.invert_fraction = e.GetDouble("invert_fraction", 0.0);
    c.effects.gain = e.GetDouble("gain", 1.0);
    c.effects.bias = e.GetDouble("bias", 0.0);
    c.effects.blur_sigma_px = e.GetDouble("blur_sigma_px", 0.0);
  }
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
                       "repeat", "destinations"});
  Scenario s;
  s.source = source;
  s.name = root.GetString("name", std::filesystem::path(source).stem().string());
  s.description = root.GetString("description", "");
  s.seed = static_cast<std::uint64_t>(root.GetInt("seed", 1));
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
    repeat.CheckKnownKeys({"start", "variant"});
    if (repeat.Has("start")) s.repeat_start = PoseDeg(repeat, "start");
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
