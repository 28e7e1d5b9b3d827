// A world, its textures and objects, and how it changes between sessions, from a scenario's YAML
// (sim/world_yaml.h).
#include "mapless/sim/world_yaml.h"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "mapless/core/check.h"
#include "mapless/io/limits.h"

namespace mapless::sim::yaml {

std::uint64_t MixSeed(std::uint64_t a, std::uint64_t b) {
  std::uint64_t z = a * 0x9E3779B97F4A7C15ULL + b + 0x632BE59BD9B4E019ULL;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  return z ^ (z >> 31);
}

TextureSpec ParseTexture(const YamlMap& m, std::uint64_t default_seed,
                         const std::string& base_dir) {
  m.CheckKnownKeys(
      {"type", "seed", "texel_m", "fit", "mean", "contrast", "size_px", "file", "changed"});
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
  t.changed = m.GetDouble("changed", t.changed);
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

// A scenario's `sessions:` block (sim/sessions.h); every tag that comes and goes must be an
// object's.
WorldChange ParseWorldChange(const YamlMap& m, const World& world) {
  m.CheckKnownKeys({"brightness", "contrast", "light_swing", "light_turn_deg", "texture",
                    "come_and_go", "presence"});
  WorldChange c;
  c.brightness = m.GetDouble("brightness", c.brightness);
  c.contrast = m.GetDouble("contrast", c.contrast);
  c.light_swing = m.GetDouble("light_swing", c.light_swing);
  c.light_turn_deg = m.GetDouble("light_turn_deg", c.light_turn_deg);
  c.texture = m.GetDouble("texture", c.texture);
  c.presence = m.GetDouble("presence", c.presence);
  if (m.Has("come_and_go")) c.come_and_go = m.GetStrings("come_and_go");
  for (const std::string& tag : c.come_and_go) {
    const bool known = std::any_of(world.objects.begin(), world.objects.end(),
                                   [&](const WorldObject& o) { return o.tag == tag; });
    if (!known) m.Fail("come_and_go", "no object has the tag '" + tag + "'");
  }
  try {
    c.Validate();
  } catch (const InputError& e) {
    m.Fail("", e.what());
  }
  return c;
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

}  // namespace mapless::sim::yaml
