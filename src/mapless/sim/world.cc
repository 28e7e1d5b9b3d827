#include "mapless/sim/world.h"

#include <algorithm>
#include <cmath>
#include <limits>

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
    MAPLESS_CHECK(ceiling_height_m > 0.0,
                  "World.ceiling_height_m = " << ceiling_height_m << "; must be > 0");
  }
  for (std::size_t i = 0; i < objects.size(); ++i) {
    const WorldObject& o = objects[i];
    const std::string name =
        std::string("World.objects[") + std::to_string(i) + "] (" + KindName(o.kind) + ")";
    o.texture.Validate();
    MAPLESS_CHECK(o.height_m > 0.0, name << ".height_m = " << o.height_m << "; must be > 0");
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
