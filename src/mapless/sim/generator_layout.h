// The inside of the world generator (generator.h): a world as it is drawn, before it is written as
// a scenario. generator.cc draws the taught path, generator_world.cc the objects of each kind of
// world and the YAML text.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "mapless/core/rng.h"

namespace mapless::sim::gen {

inline constexpr double kPi = 3.141592653589793;

// An object's footprint on the ground, for clearances.
struct Footprint {
  enum Kind { kSegment, kBox, kCircle } kind = kCircle;
  Eigen::Vector2d a = Eigen::Vector2d::Zero(), b = Eigen::Vector2d::Zero();  // segment
  Eigen::Vector2d center = Eigen::Vector2d::Zero();
  Eigen::Vector2d half = Eigen::Vector2d::Zero();  // box: half length, half width
  double yaw_rad = 0.0;                            // box
  double radius_m = 0.0;                           // circle
};
// Distance from a point to the footprint (negative inside a box or circle).
double Distance(const Footprint& f, const Eigen::Vector2d& p);

// A fixed-point number as the YAML text writes it.
std::string Num(double v, int precision = 2);

struct PathPoint {
  Eigen::Vector2d p = Eigen::Vector2d::Zero();
  double s_m = 0.0;  // along the path from the start (negative behind it)
};

struct PathItem {
  bool rotate = false;
  Eigen::Vector2d target = Eigen::Vector2d::Zero();
  double rotate_rad = 0.0;
};

struct Layout {
  explicit Layout(Rng r) : rng(r) {}
  Rng rng;
  std::uint64_t seed = 1;
  std::string kind;
  bool textureless = false;
  bool with_obstacle = false;
  std::vector<PathPoint> dense;  // the taught path every 0.1 m, from 1.5 m behind the start
  std::vector<PathItem> steps;   // teach.path
  std::vector<std::string> features;
  std::vector<Footprint> solids;                // every object of the world, for clearances
  std::vector<std::string> objects;             // their YAML items
  std::vector<std::string> added;               // repeat.variant.add items
  std::vector<std::string> labels;              // "key: value" lines
  std::vector<Eigen::Vector2d> destinations;    // for the visual potential
  std::string level;                            // texture: rich, medium, poor, none
  std::string ground;                           // world.ground's YAML
  std::string ceiling;                          // world.ceiling's YAML ("": open sky)
  double repeat_gain = 1.0, repeat_bias = 0.0;  // the repeat's light (camera effects)

  void DrawPath(double target_length_m, double separation_m);
  double length_m() const;
  // The dense path's point at s_m along it, and its direction there.
  Eigen::Vector2d PointAt(double s_m, Eigen::Vector2d* tangent = nullptr) const;
  Eigen::Vector4d PathBounds() const;  // min x, min y, max x, max y
  double ClearanceToPath(const Footprint& f) const;
  double ClearanceToSolids(const Eigen::Vector2d& p) const;
  // At least path_clearance_m from the path and object_gap_m from every object so far.
  bool Fits(const Footprint& f, double path_clearance_m, double object_gap_m) const;
};

// Draws the path and the objects of layout->kind.
void BuildWorld(Layout* layout);
std::string WriteYaml(const Layout& layout);

}  // namespace mapless::sim::gen
