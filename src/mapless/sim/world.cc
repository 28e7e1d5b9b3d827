#include "mapless/sim/world.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>

#include "mapless/core/check.h"

namespace mapless::sim {
namespace {

double DistanceToSegment(const Eigen::Vector2d& p, const Eigen::Vector2d& a,
                         const Eigen::Vector2d& b) {
  const Eigen::Vector2d ab = b - a;
  const double len2 = ab.squaredNorm();
  const double t = len2 > 0.0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
  return (a + t * ab - p).norm();
}

// Signed distance to an oriented rectangle (negative inside).
double DistanceToBox(const Eigen::Vector2d& p, const WorldObject& box) {
  const double c = std::cos(box.yaw_rad);
  const double s = std::sin(box.yaw_rad);
  const Eigen::Vector2d d = p - box.center;
  const Eigen::Vector2d local(c * d.x() + s * d.y(), -s * d.x() + c * d.y());
  const Eigen::Vector2d q = local.cwiseAbs() - 0.5 * box.size_m;
  const double outside = q.cwiseMax(0.0).norm();
  const double inside = std::min(std::max(q.x(), q.y()), 0.0);
  return outside + inside;
}

const char* KindName(ObjectKind kind) {
  switch (kind) {
    case ObjectKind::kWall:
      return "wall";
    case ObjectKind::kBox:
      return "box";
    case ObjectKind::kCylinder:
      return "cylinder";
    case ObjectKind::kPoster:
      return "poster";
  }
  return "?";
}

}  // namespace

void World::Validate() const {
  ground.Validate();
  if (ceiling) {
    ceiling->Validate();
    MAPLESS_CHECK(ceiling_height_m > 0.0 && ceiling_height_m <= kMaxObjectSizeM,
                  "World.ceiling_height_m = " << ceiling_height_m << "; must be in (0, "
                                              << kMaxObjectSizeM << "]");
  }
  MAPLESS_CHECK(
      sky_top >= 0.0 && sky_top <= 255.0 && sky_horizon >= 0.0 && sky_horizon <= 255.0,
      "World.sky: top " << sky_top << ", horizon " << sky_horizon << "; grey levels in [0, 255]");
  MAPLESS_CHECK(
      !light_azimuth_deg || std::isfinite(*light_azimuth_deg),
      "World.light_azimuth_deg = " << light_azimuth_deg.value_or(0.0) << "; must be finite");
  MAPLESS_CHECK(objects.size() <= kMaxWorldObjects,
                "World.objects: " << objects.size() << " objects (after rooms and repeats); the "
                                  << "limit is " << kMaxWorldObjects);
  std::set<TextureKey> textures = {TextureKeyOf(ground)};
  if (ceiling) textures.insert(TextureKeyOf(*ceiling));
  for (const WorldObject& o : objects) textures.insert(TextureKeyOf(o.texture));
  double texels = 0.0;
  for (const TextureKey& key : textures) texels += std::pow(std::get<6>(key), 2.0);
  MAPLESS_CHECK(texels <= kMaxTextureTexels,
                "World: " << textures.size() << " distinct textures of " << texels / (1 << 20)
                          << " M texels in all; the limit is " << kMaxTextureTexels / (1 << 20)
                          << " M (give repeated objects one texture seed, or a smaller size_px)");
  const auto coordinate_ok = [](const Eigen::Vector2d& p) {
    return p.allFinite() && p.cwiseAbs().maxCoeff() <= kMaxWorldCoordinateM;
  };
  const auto size_ok = [](double v) { return std::isfinite(v) && v > 0.0 && v <= kMaxObjectSizeM; };
  for (std::size_t i = 0; i < objects.size(); ++i) {
    const WorldObject& o = objects[i];
    const std::string name =
        std::string("World.objects[") + std::to_string(i) + "] (" + KindName(o.kind) + ")";
    o.texture.Validate();
    MAPLESS_CHECK(size_ok(o.height_m), name << ".height_m = " << o.height_m << "; must be in (0, "
                                            << kMaxObjectSizeM << "]");
    MAPLESS_CHECK(
        coordinate_ok(o.a) && coordinate_ok(o.b) && coordinate_ok(o.center),
        name << ": a coordinate is beyond " << kMaxWorldCoordinateM << " m from the origin");
    MAPLESS_CHECK(
        std::isfinite(o.yaw_rad) && std::isfinite(o.z_m) && std::abs(o.z_m) <= kMaxObjectSizeM,
        name << ": yaw or height above the ground out of range");
    MAPLESS_CHECK(o.kind == ObjectKind::kWall || o.kind == ObjectKind::kCylinder ||
                      (size_ok(o.size_m.x()) && size_ok(o.size_m.y())),
                  name << ".size = [" << o.size_m.x() << ", " << o.size_m.y()
                       << "]; each must be in (0, " << kMaxObjectSizeM << "] m");
    MAPLESS_CHECK(
        o.kind != ObjectKind::kCylinder || size_ok(o.radius_m),
        name << ".radius_m = " << o.radius_m << "; must be in (0, " << kMaxObjectSizeM << "]");
    MAPLESS_CHECK(std::isfinite(o.appears_s) && o.appears_s >= 0.0 && !std::isnan(o.leaves_s) &&
                      o.leaves_s > o.appears_s,
                  name << ": appears at " << o.appears_s << " s, leaves at " << o.leaves_s
                       << " s; expected 0 <= appears < leaves");
    switch (o.kind) {
      case ObjectKind::kWall:
        MAPLESS_CHECK((o.b - o.a).norm() > 1e-6, name << ": wall ends must differ");
        break;
      case ObjectKind::kBox:
      case ObjectKind::kPoster:
        MAPLESS_CHECK(o.size_m.x() > 0.0 && o.size_m.y() > 0.0, name << ".size = [" << o.size_m.x()
                                                                     << ", " << o.size_m.y()
                                                                     << "]; both must be > 0");
        break;
      case ObjectKind::kCylinder:
        MAPLESS_CHECK(o.radius_m > 0.0, name << ".radius_m = " << o.radius_m << "; must be > 0");
        break;
    }
  }
}

World ApplyVariant(const World& world, const WorldVariant& variant) {
  auto has_tag = [&](const std::string& tag) {
    return std::any_of(world.objects.begin(), world.objects.end(),
                       [&](const WorldObject& o) { return o.tag == tag; });
  };
  for (const auto& tag : variant.remove) {
    MAPLESS_CHECK(has_tag(tag), "variant.remove: no object has tag '" << tag << "'");
  }
  for (const auto& [tag, delta] : variant.move_m) {
    MAPLESS_CHECK(has_tag(tag), "variant.move: no object has tag '" << tag << "'");
  }
  for (const auto& leaving : variant.leave_s) {
    const std::string& tag = leaving.first;
    const double t = leaving.second;
    const bool added = std::any_of(variant.add.begin(), variant.add.end(),
                                   [&](const WorldObject& o) { return o.tag == tag; });
    MAPLESS_CHECK(has_tag(tag) || added, "variant.leave_s: no object has tag '" << tag << "'");
    MAPLESS_CHECK(std::isfinite(t) && t >= 0.0,
                  "variant.leave_s." << tag << " = " << t << "; must be a time >= 0 s");
  }
  World out = world;
  out.objects.clear();
  for (const WorldObject& o : world.objects) {
    if (!o.tag.empty() &&
        std::find(variant.remove.begin(), variant.remove.end(), o.tag) != variant.remove.end()) {
      continue;
    }
    WorldObject moved = o;
    const auto it = variant.move_m.find(o.tag);
    if (!o.tag.empty() && it != variant.move_m.end()) {
      moved.a += it->second;
      moved.b += it->second;
      moved.center += it->second;
    }
    out.objects.push_back(moved);
  }
  out.objects.insert(out.objects.end(), variant.add.begin(), variant.add.end());
  for (WorldObject& o : out.objects) {
    const auto it = variant.leave_s.find(o.tag);
    if (!o.tag.empty() && it != variant.leave_s.end()) o.leaves_s = it->second;
  }
  return out;
}

void WorldChange::Validate() const {
  MAPLESS_CHECK(std::abs(brightness) <= 50.0,
                "sessions.brightness = " << brightness << "; must be in [-50, 50] grey levels");
  MAPLESS_CHECK(std::abs(contrast) <= 0.2,
                "sessions.contrast = " << contrast << "; must be in [-0.2, 0.2]");
  MAPLESS_CHECK(light_swing >= 0.0 && light_swing <= 100.0,
                "sessions.light_swing = " << light_swing << "; must be in [0, 100] grey levels");
  MAPLESS_CHECK(std::abs(light_turn_deg) <= 180.0,
                "sessions.light_turn_deg = " << light_turn_deg << "; must be in [-180, 180]");
  MAPLESS_CHECK(texture >= 0.0 && texture <= 1.0,
                "sessions.texture = " << texture << "; must be in [0, 1]");
  MAPLESS_CHECK(presence >= 0.0 && presence <= 1.0,
                "sessions.presence = " << presence << "; must be in [0, 1]");
}

World WorldAt(const World& world, double t_s) {
  World out = world;
  out.objects.clear();
  for (const WorldObject& o : world.objects)
    if (o.appears_s <= t_s && t_s < o.leaves_s) out.objects.push_back(o);
  return out;
}

std::vector<double> ChangeTimes(const World& world) {
  std::vector<double> out;
  for (const WorldObject& o : world.objects) {
    if (o.appears_s > 0.0) out.push_back(o.appears_s);
    if (std::isfinite(o.leaves_s) && o.leaves_s > 0.0) out.push_back(o.leaves_s);
  }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

double ClearanceTo(const World& world, double x_m, double y_m) {
  const Eigen::Vector2d p(x_m, y_m);
  double best = std::numeric_limits<double>::infinity();
  for (const WorldObject& o : world.objects) {
    switch (o.kind) {
      case ObjectKind::kWall:
        best = std::min(best, DistanceToSegment(p, o.a, o.b));
        break;
      case ObjectKind::kBox:
        best = std::min(best, DistanceToBox(p, o));
        break;
      case ObjectKind::kCylinder:
        best = std::min(best, (p - o.center).norm() - o.radius_m);
        break;
      case ObjectKind::kPoster:
        break;
    }
  }
  return best;
}

Eigen::Vector4d FootprintBounds(const World& world) {
  Eigen::Vector4d b(1e9, 1e9, -1e9, -1e9);
  auto add = [&](const Eigen::Vector2d& p, double r) {
    b[0] = std::min(b[0], p.x() - r);
    b[1] = std::min(b[1], p.y() - r);
    b[2] = std::max(b[2], p.x() + r);
    b[3] = std::max(b[3], p.y() + r);
  };
  for (const WorldObject& o : world.objects) {
    switch (o.kind) {
      case ObjectKind::kWall:
        add(o.a, 0);
        add(o.b, 0);
        break;
      case ObjectKind::kBox:
        add(o.center, 0.5 * o.size_m.norm());
        break;
      case ObjectKind::kCylinder:
        add(o.center, o.radius_m);
        break;
      case ObjectKind::kPoster:
        add(o.center, 0.5 * o.size_m.x());
        break;
    }
  }
  if (b[0] > b[2]) b = Eigen::Vector4d(-1, -1, 1, 1);
  return b;
}

}  // namespace mapless::sim
