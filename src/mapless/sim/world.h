// The simulated world: a textured ground plane, an optional ceiling, a sky, and objects standing on
// the ground: walls (vertical rectangles), boxes (cars, chairs, cupboards), cylinders (pillars,
// bins) and flat posters. Objects carry tags so that a variant of the same world can remove or move
// them (the papers' "two parked cars left during the repeat").
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "mapless/sim/texture.h"

namespace mapless::sim {

// Limits on a world, checked by World::Validate() (docs/hardening.md says why each is where it is).
inline constexpr double kMaxWorldCoordinateM = 10'000.0;  // |x|, |y| of every point, metres
inline constexpr double kMaxObjectSizeM = 1'000.0;        // sizes, radii, heights, metres
inline constexpr std::size_t kMaxWorldObjects = 2'000;    // after `room` and `repeat` expansion
// Distinct textures are generated and kept for rendering: the sum of their size_px^2.
inline constexpr double kMaxTextureTexels = 128.0 * 1024 * 1024;

enum class ObjectKind { kWall, kBox, kCylinder, kPoster };

struct WorldObject {
  ObjectKind kind = ObjectKind::kBox;
  std::string tag;  // optional; used by variants
  TextureSpec texture;
  // kWall: a vertical rectangle from `a` to `b` on the ground, `height_m` tall.
  Eigen::Vector2d a = Eigen::Vector2d::Zero();
  Eigen::Vector2d b = Eigen::Vector2d::Zero();
  // kBox: centre, footprint `size_m` (length along yaw, width), `height_m`, heading `yaw_rad`.
  // kCylinder: centre, `radius_m`, `height_m`.
  // kPoster: centre (x, y) at height `z_m` (poster centre), `size_m` = (width, height), facing
  //          direction `yaw_rad` (the side it is seen from).
  Eigen::Vector2d center = Eigen::Vector2d::Zero();
  Eigen::Vector2d size_m = Eigen::Vector2d::Zero();
  double height_m = 1.0;
  double radius_m = 0.2;
  double yaw_rad = 0.0;
  double z_m = 1.0;
  // Simulated time (s) at which the object is put down and taken away: it is in the world for
  // appears_s <= t < leaves_s (a box left on the path, a parked car that drives off).
  double appears_s = 0.0;
  double leaves_s = std::numeric_limits<double>::infinity();
  bool timed() const { return appears_s > 0.0 || std::isfinite(leaves_s); }
};

struct World {
  TextureSpec ground;
  std::optional<TextureSpec> ceiling;  // indoor worlds
  double ceiling_height_m = 2.6;
  double sky_top = 205.0;      // sky intensity at the top of the image
  double sky_horizon = 175.0;  // sky intensity at the bottom of the image
  // Where the light comes from, degrees counter-clockwise from +x (its elevation is fixed, about
  // 50 degrees): which faces of walls and boxes are lit. Unset: 57.5 degrees.
  std::optional<double> light_azimuth_deg;
  std::vector<WorldObject> objects;

  void Validate() const;  // throws InputError naming the object and field
};

// A variant of a world (what has changed at repeat time): objects removed or moved by tag, objects
// that are new, and objects that leave during the repeat.
struct WorldVariant {
  std::vector<std::string> remove;                // tags to remove
  std::map<std::string, Eigen::Vector2d> move_m;  // tag -> displacement (dx, dy)
  std::vector<WorldObject> add;                   // new objects (they may carry their own times)
  std::map<std::string, double> leave_s;          // tag -> simulated time (s) it leaves at
};

// How a world changes from one session to the next (sim/sessions.h; a scenario's `sessions:`).
struct WorldChange {
  double brightness = -1.5;     // grey levels per session (negative: towards dusk)
  double contrast = -0.015;     // camera gain per session (1 at session 0)
  double light_swing = 8.0;     // grey levels: each session's brightness varies by up to +-this
  double light_turn_deg = 9.0;  // the light's direction turns by this per session
  double texture = 0.03;        // share of every surface's texture changed per session
  std::vector<std::string> come_and_go;  // tags of objects that are there on a session or not
  double presence = 0.5;                 // the chance that each of them is there
  void Validate() const;                 // throws InputError naming the field
};

// Returns the world with the variant applied (remove, move, add, then the leaving times); throws
// InputError for a tag no object has.
World ApplyVariant(const World& world, const WorldVariant& variant);

// The objects in the world at simulated time t_s (appears_s <= t_s < leaves_s).
World WorldAt(const World& world, double t_s);
// The times (s, > 0, sorted, distinct) at which an object of `world` appears or leaves.
std::vector<double> ChangeTimes(const World& world);

// Distance from point (x, y) to the nearest obstacle footprint (walls, boxes, cylinders; posters
// hang on walls and do not count). Negative inside a box or cylinder.
double ClearanceTo(const World& world, double x_m, double y_m);

// Axis-aligned bounds of all object footprints: (min_x, min_y, max_x, max_y).
Eigen::Vector4d FootprintBounds(const World& world);

}  // namespace mapless::sim
