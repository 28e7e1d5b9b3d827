// The objects of each kind of generated world, the object on the path, the labels and the YAML
// text (generator_layout.h).
#include <algorithm>
#include <cmath>
#include <sstream>

#include "mapless/sim/generator_layout.h"

namespace mapless::sim::gen {

namespace {

constexpr double kRobotRadiusM = 0.2;

Eigen::Vector2d Left(const Eigen::Vector2d& t) { return {-t.y(), t.x()}; }
double Yaw(const Eigen::Vector2d& t) { return std::atan2(t.y(), t.x()); }

// A texture of the world's level: surfaces (floors, walls, ceilings) take the level drawn for the
// world; objects at least a medium contrast (things people put down are seldom plain), except in
// a world without any texture.
std::string Texture(Layout* l, const std::string& type, double texel_m, double mean, bool surface) {
  double lo = 0.8, hi = 1.0;
  if (l->level == "none") {
    lo = hi = 0.0;
  } else if (l->level == "poor" && surface) {
    lo = 0.22, hi = 0.32;
  } else if (l->level == "medium" || l->level == "poor") {
    lo = 0.45, hi = 0.65;
  }
  const double contrast = l->rng.Uniform(lo, hi);
  const std::string t = l->level == "none" ? "plain" : type;
  return "{type: " + t + ", texel_m: " + Num(texel_m, 4) + ", mean: " + Num(mean, 0) +
         ", contrast: " + Num(contrast, 2) + "}";
}

std::string Pick(Rng& rng, const std::vector<std::string>& options) {
  return options[rng.UniformInt(options.size())];
}

void AddBox(Layout* l, const Eigen::Vector2d& c, const Eigen::Vector3d& size, double yaw,
            const std::string& texture) {
  Footprint f;
  f.kind = Footprint::kBox;
  f.center = c;
  f.half = 0.5 * size.head<2>();
  f.yaw_rad = yaw;
  l->solids.push_back(f);
  l->objects.push_back("{type: box, center: [" + Num(c.x()) + ", " + Num(c.y()) + "], size_m: [" +
                       Num(size.x()) + ", " + Num(size.y()) + ", " + Num(size.z()) +
                       "], yaw_deg: " + Num(yaw * 180.0 / kPi, 1) + ", texture: " + texture + "}");
}

void AddCylinder(Layout* l, const Eigen::Vector2d& c, double r, double h,
                 const std::string& texture) {
  Footprint f;
  f.center = c;
  f.radius_m = r;
  l->solids.push_back(f);
  l->objects.push_back("{type: cylinder, center: [" + Num(c.x()) + ", " + Num(c.y()) +
                       "], radius_m: " + Num(r) + ", height_m: " + Num(h) +
                       ", texture: " + texture + "}");
}

void AddWall(Layout* l, const std::vector<Eigen::Vector2d>& points, double h,
             const std::string& texture) {
  std::string yaml = "{type: wall, height_m: " + Num(h) + ", texture: " + texture + ", points: [";
  for (std::size_t i = 0; i < points.size(); ++i) {
    yaml += (i ? ", [" : "[") + Num(points[i].x()) + ", " + Num(points[i].y()) + "]";
    if (i > 0) {
      Footprint f;
      f.kind = Footprint::kSegment;
      f.a = points[i - 1];
      f.b = points[i];
      l->solids.push_back(f);
    }
  }
  l->objects.push_back(yaml + "]}");
}

// A picture on a wall at (x, y), facing `facing` (radians), its lower edge above the floor.
void AddPoster(Layout* l, const Eigen::Vector2d& p, double facing) {
  const double w = l->rng.Uniform(0.6, 1.3), h = l->rng.Uniform(0.5, 1.1);
  const double z = l->rng.Uniform(0.9, 1.5);
  const std::string texture = l->level == "none" ? "{type: plain, contrast: 0}" : "{type: poster}";
  l->objects.push_back("{type: poster, center: [" + Num(p.x()) + ", " + Num(p.y()) + ", " + Num(z) +
                       "], size_m: [" + Num(w) + ", " + Num(h) + "], facing_deg: " +
                       Num(facing * 180.0 / kPi, 1) + ", texture: " + texture + "}");
}

// Objects beside the path: `count` tries at a lateral offset in [near_m, far_m] (near side),
// each kept when it fits.
void Clutter(Layout* l, int count, double near_m, double far_m) {
  for (int i = 0, placed = 0; i < 40 * count && placed < count; ++i) {
    Eigen::Vector2d t;
    const Eigen::Vector2d p = l->PointAt(l->rng.Uniform(0.0, l->length_m()), &t);
    const double side = l->rng.Uniform() < 0.5 ? 1.0 : -1.0;
    const double offset = l->rng.Uniform(near_m, far_m);
    const std::string tex = Texture(l, Pick(l->rng, {"blobs", "noise", "tiles"}), 0.004,
                                    l->rng.Uniform(60, 200), false);
    Footprint f;
    if (l->rng.Uniform() < 0.6) {
      const Eigen::Vector3d size(l->rng.Uniform(0.3, 0.9), l->rng.Uniform(0.3, 0.9),
                                 l->rng.Uniform(0.4, 1.2));
      f.kind = Footprint::kBox;
      f.center = p + side * (offset + 0.5 * size.y()) * Left(t);
      f.half = 0.5 * size.head<2>();
      f.yaw_rad = Yaw(t) + l->rng.Uniform(-0.4, 0.4);
      if (!l->Fits(f, near_m, 0.3)) continue;
      AddBox(l, f.center, size, f.yaw_rad, tex);
    } else {
      f.radius_m = l->rng.Uniform(0.1, 0.3);
      f.center = p + side * (offset + f.radius_m) * Left(t);
      if (!l->Fits(f, near_m, 0.3)) continue;
      AddCylinder(l, f.center, f.radius_m, l->rng.Uniform(0.5, 1.8), tex);
    }
    ++placed;
  }
}

// Two boxes facing each other across the path, 0.5 m from it on each side: a passage 1 m wide
// for a robot 0.4 m across.
void NarrowPassage(Layout* l) {
  for (int i = 0; i < 40; ++i) {
    Eigen::Vector2d t;
    const Eigen::Vector2d p = l->PointAt(l->rng.Uniform(2.0, l->length_m() - 2.0), &t);
    const Eigen::Vector3d size(0.6, 0.5, 0.8);
    Footprint a, b;
    a.kind = b.kind = Footprint::kBox;
    a.half = b.half = 0.5 * size.head<2>();
    a.yaw_rad = b.yaw_rad = Yaw(t);
    a.center = p + 0.75 * Left(t);
    b.center = p - 0.75 * Left(t);
    if (!l->Fits(a, 0.45, 0.3) || !l->Fits(b, 0.45, 0.3)) continue;
    const std::string tex = Texture(l, "blobs", 0.004, l->rng.Uniform(70, 190), false);
    AddBox(l, a.center, size, a.yaw_rad, tex);
    AddBox(l, b.center, size, b.yaw_rad, tex);
    l->features.push_back("narrow_passage");
    return;
  }
}

void Indoor(Layout* l) {
  l->DrawPath(l->rng.Uniform(9.0, 14.0), 1.5);
  const Eigen::Vector4d b = l->PathBounds();
  const Eigen::Vector2d lo(b[0] - l->rng.Uniform(1.0, 2.0), b[1] - l->rng.Uniform(1.0, 2.0));
  const Eigen::Vector2d hi(b[2] + l->rng.Uniform(1.0, 2.0), b[3] + l->rng.Uniform(1.0, 2.0));
  const double height = l->rng.Uniform(2.5, 3.0);
  l->ground =
      Texture(l, Pick(l->rng, {"tiles", "noise", "blobs"}), 0.003, l->rng.Uniform(105, 145), true);
  l->ceiling = "{height_m: " + Num(height) +
               ", texture: " + Texture(l, Pick(l->rng, {"tiles", "plain"}), 0.005, 205, true) + "}";
  AddWall(l, {lo, {hi.x(), lo.y()}, hi, {lo.x(), hi.y()}, lo}, height,
          Texture(l, Pick(l->rng, {"noise", "bricks", "tiles"}), 0.004, l->rng.Uniform(130, 185),
                  true));
  const int posters = 4 + static_cast<int>(l->rng.UniformInt(6));
  for (int i = 0; i < posters; ++i) {
    const int side = static_cast<int>(l->rng.UniformInt(4));
    const double u = l->rng.Uniform(0.1, 0.9);
    const Eigen::Vector2d p =
        side == 0   ? Eigen::Vector2d(lo.x() + u * (hi.x() - lo.x()), lo.y() + 0.02)
        : side == 1 ? Eigen::Vector2d(hi.x() - 0.02, lo.y() + u * (hi.y() - lo.y()))
        : side == 2 ? Eigen::Vector2d(lo.x() + u * (hi.x() - lo.x()), hi.y() - 0.02)
                    : Eigen::Vector2d(lo.x() + 0.02, lo.y() + u * (hi.y() - lo.y()));
    AddPoster(l, p, side * kPi / 2 + kPi / 2);
  }
  if (l->rng.Uniform() < 0.35) NarrowPassage(l);
  Clutter(l, 4 + static_cast<int>(l->rng.UniformInt(7)), 0.7, 1.8);
}

void Corridor(Layout* l) {
  const bool narrow = l->rng.Uniform() < 0.25;
  const double w = narrow ? l->rng.Uniform(1.2, 1.45) : l->rng.Uniform(1.7, 2.6);
  l->DrawPath(l->rng.Uniform(10.0, 15.0), w + 1.2);
  if (narrow) l->features.push_back("narrow_passage");
  const double height = l->rng.Uniform(2.4, 2.8);
  l->ground =
      Texture(l, Pick(l->rng, {"tiles", "noise", "blobs"}), 0.003, l->rng.Uniform(105, 145), true);
  l->ceiling = "{height_m: " + Num(height) +
               ", texture: " + Texture(l, Pick(l->rng, {"tiles", "plain"}), 0.005, 205, true) + "}";
  // The walls follow the path (from 1.5 m behind the start to 1.5 m beyond the end) at +-w/2.
  std::vector<Eigen::Vector2d> centre;
  std::vector<Eigen::Vector2d> tangent;
  for (std::size_t i = 0; i < l->dense.size(); i += 5) {
    const std::size_t j = std::min(i + 3, l->dense.size() - 1), k = i >= 3 ? i - 3 : 0;
    centre.push_back(l->dense[i].p);
    tangent.push_back((l->dense[j].p - l->dense[k].p).normalized());
  }
  Eigen::Vector2d end_t;
  const Eigen::Vector2d end = l->PointAt(l->length_m(), &end_t);
  if ((centre.back() - end).norm() < 0.2) {
    centre.pop_back();
    tangent.pop_back();
  }
  centre.push_back(end);
  tangent.push_back(end_t);
  centre.push_back(end + 1.5 * end_t);
  tangent.push_back(end_t);
  std::vector<Eigen::Vector2d> left, right;
  for (std::size_t i = 0; i < centre.size(); ++i) {
    left.push_back(centre[i] + 0.5 * w * Left(tangent[i]));
    right.push_back(centre[i] - 0.5 * w * Left(tangent[i]));
  }
  const std::string wall = Pick(l->rng, {"noise", "bricks", "tiles"});
  const double mean = l->rng.Uniform(130, 185);
  AddWall(l, left, height, Texture(l, wall, 0.004, mean, true));
  AddWall(l, right, height, Texture(l, wall, 0.004, mean - 10, true));
  AddWall(l, {left.front(), right.front()}, height, Texture(l, wall, 0.004, mean, true));
  AddWall(l, {left.back(), right.back()}, height, Texture(l, wall, 0.004, mean, true));
  // Doors and notices along the walls, every 2-5 m on either side.
  for (double s = l->rng.Uniform(0.5, 2.5); s < l->length_m(); s += l->rng.Uniform(2.0, 5.0)) {
    Eigen::Vector2d t;
    const Eigen::Vector2d p = l->PointAt(s, &t);
    const double side = l->rng.Uniform() < 0.5 ? 1.0 : -1.0;
    AddPoster(l, p + side * (0.5 * w - 0.02) * Left(t), Yaw(t) - side * kPi / 2);
  }
}

void Outdoor(Layout* l) {
  l->DrawPath(l->rng.Uniform(10.0, 15.0), 2.0);
  l->ground = Texture(l, Pick(l->rng, {"blobs", "noise"}), 0.004, l->rng.Uniform(95, 140), true);
  const int buildings = 2 + static_cast<int>(l->rng.UniformInt(4));
  for (int i = 0, placed = 0; i < 100 && placed < buildings; ++i) {
    Eigen::Vector2d t;
    const Eigen::Vector2d p = l->PointAt(l->rng.Uniform(0.0, l->length_m()), &t);
    const double side = l->rng.Uniform() < 0.5 ? 1.0 : -1.0;
    const Eigen::Vector3d size(l->rng.Uniform(4.0, 10.0), l->rng.Uniform(3.0, 6.0),
                               l->rng.Uniform(4.0, 9.0));
    Footprint f;
    f.kind = Footprint::kBox;
    f.center = p + side * (l->rng.Uniform(3.0, 6.0) + 0.5 * size.y()) * Left(t);
    f.half = 0.5 * size.head<2>();
    f.yaw_rad = Yaw(t);
    if (!l->Fits(f, 2.5, 0.5)) continue;
    AddBox(l, f.center, size, f.yaw_rad,
           Texture(l, Pick(l->rng, {"bricks", "tiles", "noise"}), 0.01, l->rng.Uniform(110, 190),
                   true));
    ++placed;
  }
  // Trees.
  const int trees = 6 + static_cast<int>(l->rng.UniformInt(9));
  for (int i = 0, placed = 0; i < 300 && placed < trees; ++i) {
    Eigen::Vector2d t;
    const Eigen::Vector2d p = l->PointAt(l->rng.Uniform(0.0, l->length_m()), &t);
    const double side = l->rng.Uniform() < 0.5 ? 1.0 : -1.0;
    Footprint f;
    f.radius_m = l->rng.Uniform(0.12, 0.3);
    f.center = p + side * (l->rng.Uniform(1.0, 3.5) + f.radius_m) * Left(t);
    if (!l->Fits(f, 0.8, 0.4)) continue;
    AddCylinder(l, f.center, f.radius_m, l->rng.Uniform(2.5, 5.0),
                Texture(l, "noise", 0.003, l->rng.Uniform(50, 100), false));
    ++placed;
  }
  Clutter(l, 2 + static_cast<int>(l->rng.UniformInt(4)), 0.75, 2.0);
}

void CarPark(Layout* l) {
  l->DrawPath(l->rng.Uniform(10.0, 15.0), 2.6);
  l->ground = Texture(l, Pick(l->rng, {"noise", "blobs"}), 0.004, l->rng.Uniform(90, 130), true);
  const bool underground = l->rng.Uniform() < 0.5;
  const bool across = l->rng.Uniform() < 0.4;  // cars parked across the lane, not along it
  if (underground) {
    const Eigen::Vector4d b = l->PathBounds();
    const Eigen::Vector2d lo(b[0] - 4.0, b[1] - 4.0), hi(b[2] + 4.0, b[3] + 4.0);
    l->ceiling = "{height_m: 2.6, texture: " + Texture(l, "plain", 0.01, 190, true) + "}";
    AddWall(l, {lo, {hi.x(), lo.y()}, hi, {lo.x(), hi.y()}, lo}, 2.6,
            Texture(l, "noise", 0.005, l->rng.Uniform(140, 180), true));
    for (double x = lo.x() + 2.0; x < hi.x() - 1.0; x += 5.0) {
      for (double y = lo.y() + 2.0; y < hi.y() - 1.0; y += 5.0) {
        Footprint f;
        f.center = {x, y};
        f.radius_m = 0.3;
        if (l->Fits(f, 1.0, 0.5))
          AddCylinder(l, f.center, 0.3, 2.6, Texture(l, "noise", 0.004, 160, false));
      }
    }
  }
  for (double s = l->rng.Uniform(0.0, 1.5); s < l->length_m(); s += l->rng.Uniform(2.3, 3.2)) {
    Eigen::Vector2d t;
    const Eigen::Vector2d p = l->PointAt(s, &t);
    for (double side : {1.0, -1.0}) {
      if (l->rng.Uniform() > 0.65) continue;
      const double near = l->rng.Uniform(0.9, 1.6);
      Footprint f;
      f.kind = Footprint::kBox;
      f.half = {2.1, 0.9};
      f.yaw_rad = Yaw(t) + (across ? kPi / 2 : 0.0);
      f.center = p + side * (near + (across ? 2.1 : 0.9)) * Left(t);
      if (!l->Fits(f, 0.85, 0.25)) continue;
      AddBox(l, f.center, {4.2, 1.8, l->rng.Uniform(1.4, 1.7)}, f.yaw_rad,
             Texture(l, Pick(l->rng, {"blobs", "noise"}), 0.004, l->rng.Uniform(50, 210), false));
    }
  }
}

// An object on the path, put there after the teach; 3 m or more after the start, 2 m or more
// before the end.
void ObstacleOnPath(Layout* l) {
  for (int i = 0; i < 40; ++i) {
    const double s = l->rng.Uniform(std::max(3.0, 0.3 * l->length_m()), l->length_m() - 2.0);
    const Eigen::Vector2d p = l->PointAt(s);
    if (l->ClearanceToSolids(p) < 0.9) continue;
    const double mean = l->rng.Uniform() < 0.5 ? l->rng.Uniform(50, 90) : l->rng.Uniform(170, 210);
    const std::string tex = Texture(l, Pick(l->rng, {"blobs", "noise"}), 0.004, mean, false);
    if (l->rng.Uniform() < 0.6) {
      const double side = l->rng.Uniform(0.4, 0.6);
      l->added.push_back("{type: box, tag: on_path, center: [" + Num(p.x()) + ", " + Num(p.y()) +
                         "], size_m: [" + Num(side) + ", " + Num(side) + ", " +
                         Num(l->rng.Uniform(0.4, 0.7)) + "], texture: " + tex + "}");
    } else {
      l->added.push_back("{type: cylinder, tag: on_path, center: [" + Num(p.x()) + ", " +
                         Num(p.y()) + "], radius_m: " + Num(l->rng.Uniform(0.18, 0.25)) +
                         ", height_m: " + Num(l->rng.Uniform(0.6, 0.9)) + ", texture: " + tex +
                         "}");
    }
    l->labels.push_back("obstacle_on_path: on_path");
    l->labels.push_back("obstacle_at_m: \"" + Num(s, 1) + "\"");
    return;
  }
  l->labels.push_back("obstacle_on_path: none");
}

// A destination for the visual potential: the path's point farthest from the start (2.5 m or
// more along it) that the robot sees in a straight line with 0.6 m to spare on each side.
void Destination(Layout* l) {
  Eigen::Vector2d best = l->PointAt(2.5);
  for (const PathPoint& q : l->dense) {
    if (q.s_m < 2.5 || q.p.norm() <= best.norm()) continue;
    bool clear = l->ClearanceToSolids(q.p) >= 0.8;
    const int n = static_cast<int>(std::ceil(q.p.norm() / 0.1));
    for (int i = 0; clear && i <= n; ++i)
      clear = l->ClearanceToSolids(q.p * (static_cast<double>(i) / n)) >= 0.6;
    if (clear) best = q.p;
  }
  l->destinations.push_back(best);
}

}  // namespace

void BuildWorld(Layout* l) {
  if (l->textureless) {
    l->level = "none";
  } else {
    const double u = l->rng.Uniform();
    l->level = u < 0.2 ? "poor" : u < 0.55 ? "medium" : "rich";
  }
  if (l->kind == "corridor") {
    Corridor(l);
  } else if (l->kind == "outdoor") {
    Outdoor(l);
  } else if (l->kind == "car_park") {
    CarPark(l);
  } else {
    Indoor(l);
  }
  l->repeat_gain = l->rng.Uniform(0.8, 1.2);
  l->repeat_bias = l->rng.Uniform(-25.0, 20.0);
  if (l->with_obstacle) {
    ObstacleOnPath(l);
  } else {
    l->labels.push_back("obstacle_on_path: none");
  }
  Destination(l);
  (void)kRobotRadiusM;
}

std::string WriteYaml(const Layout& l) {
  std::ostringstream y;
  const std::string name = "gen_" + l.kind + "_" + std::to_string(l.seed);
  std::string features;
  for (const std::string& f : l.features) features += (features.empty() ? "" : " ") + f;
  y << "# Generated by `mapless sim generate --seed " << l.seed << " --kind " << l.kind
    << "` (src/mapless/sim/generator.h).\n";
  y << "name: " << name << "\n";
  y << "description: a generated " << l.kind << " world, a " << Num(l.length_m(), 1) << " m route ("
    << features << "), " << l.level << " texture\n";
  y << "seed: " << l.seed << "\n";
  y << "labels:\n";
  y << "  generator: mapless sim generate\n";
  y << "  kind: " << l.kind << "\n";
  y << "  path_m: \"" << Num(l.length_m(), 1) << "\"\n";
  y << "  features: " << features << "\n";
  y << "  texture: " << l.level << "\n";
  y << "  light: \"repeat gain " << Num(l.repeat_gain) << ", bias " << Num(l.repeat_bias, 1)
    << "\"\n";
  for (const std::string& label : l.labels) y << "  " << label << "\n";
  if (l.level == "none") {
    y << "  feasible: \"false\"\n";
    y << "  why: no texture on any surface, nothing for features, flow or an eigenspace\n";
  } else {
    y << "  feasible: \"true\"\n";
  }
  y << "world:\n";
  y << "  ground: " << l.ground << "\n";
  if (!l.ceiling.empty()) y << "  ceiling: " << l.ceiling << "\n";
  y << "  objects:\n";
  for (const std::string& o : l.objects) y << "    - " << o << "\n";
  y << "camera: {width: 320, height: 240, hfov_deg: 60, height_m: 0.4}\n";
  y << "robot: {radius_m: " << Num(kRobotRadiusM) << "}\n";
  y << "teach:\n  start: [0, 0, 0]\n  speed_mps: 0.3\n  path:\n";
  for (const PathItem& s : l.steps) {
    if (s.rotate) {
      y << "    - {rotate_deg: " << Num(s.rotate_rad * 180.0 / kPi, 1) << "}\n";
    } else {
      y << "    - [" << Num(s.target.x()) << ", " << Num(s.target.y()) << "]\n";
    }
  }
  y << "repeat:\n";
  y << "  effects: {gain: " << Num(l.repeat_gain) << ", bias: " << Num(l.repeat_bias, 1) << "}\n";
  if (!l.added.empty()) {
    y << "  variant:\n    add:\n";
    for (const std::string& a : l.added) y << "      - " << a << "\n";
  }
  y << "destinations: [";
  for (std::size_t i = 0; i < l.destinations.size(); ++i)
    y << (i ? ", [" : "[") << Num(l.destinations[i].x()) << ", " << Num(l.destinations[i].y())
      << "]";
  y << "]\n";
  return y.str();
}

}  // namespace mapless::sim::gen
