// A scenario: the world, the camera and its mount, the robot, the taught path (driven by a scripted
// driver on ground truth, as a person would drive in the teach phase) and how the repeat phase
// starts (its start pose and the world variant it sees). Scenarios are YAML files; the built-in
// ones live in config/scenarios/ and are compiled into the library (see docs/simulator.md).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "mapless/sim/camera.h"
#include "mapless/sim/image_effects.h"
#include "mapless/sim/robot.h"
#include "mapless/sim/world.h"

namespace mapless::sim {

// Limits on a scenario beyond those of its world (docs/hardening.md).
inline constexpr double kMinPathSpeedMps = 0.01;
inline constexpr double kMaxPathSpeedMps = 10.0;
inline constexpr std::size_t kMaxPathSteps = 10'000;
inline constexpr double kMaxPathLengthM = 20'000.0;
inline constexpr double kMaxRotateRad = 20.0 * 3.141592653589793;  // ten turns
inline constexpr std::size_t kMaxDestinations = 1'000;

struct CameraSpec {
  CameraModel model = CameraModel::FromFov(320, 240, DegToRad(60.0));
  CameraMount mount;
  ImageEffects effects;
  double rate_hz = 10.0;  // frames per second
  void Validate() const;
};

// One step of the taught path: drive to a point, or rotate in place by an angle.
struct PathStep {
  enum class Kind { kGoTo, kRotate };
  Kind kind = Kind::kGoTo;
  Eigen::Vector2d target = Eigen::Vector2d::Zero();  // kGoTo
  double speed_mps = 0.0;                            // kGoTo; 0 = the path's default speed
  double rotate_rad = 0.0;                           // kRotate; positive = counter-clockwise
};

struct Scenario {
  std::string name;
  std::string description;
  std::string source;  // file path or "builtin:NAME"
  std::uint64_t seed = 1;
  World world;
  CameraSpec camera;
  RobotOptions robot;
  Pose2 teach_start;
  double teach_speed_mps = 0.3;
  std::vector<PathStep> teach_path;
  Pose2 repeat_start;
  WorldVariant repeat_variant;
  // The camera's effects at repeat (and follow, navigate) time instead of `camera.effects`: light
  // that differs from the teach's (`repeat: {effects: {gain, bias, ...}}`).
  std::optional<ImageEffects> repeat_effects;
  // Free labels (`labels: {key: value}`): what a generated world was drawn with (generator.h).
  std::map<std::string, std::string> labels;
  std::vector<Eigen::Vector2d> destinations;  // goals for destination-guided navigation
  std::optional<WorldChange> sessions;        // how the world changes between sessions

  void Validate() const;
  // Length of the taught path (sum of straight legs), metres.
  double PathLength() const;
};

// The scenario's area: object footprints, starts, taught path and destinations, with a margin:
// (min_x, min_y, max_x, max_y), metres.
Eigen::Vector4d ScenarioBounds(const Scenario& scenario, double margin_m);

// Parses a scenario from YAML text; errors name `source` (file), line and field.
Scenario ParseScenario(const std::string& yaml_text, const std::string& source,
                       const std::string& base_dir);
// Loads a scenario by built-in name or by file path (a name containing '/' or ending in .yaml is a
// path); throws InputError naming it when it is neither. NAME@S (a number S): session S of a world
// that changes between sessions (sessions.h: SessionScenario; `sim:lifelong_indoor@12`).
Scenario LoadScenario(const std::string& name_or_path);
// Built-in scenario names, sorted.
std::vector<std::string> BuiltinScenarioNames();
// The YAML text of a built-in scenario; empty when there is none of that name.
std::string BuiltinScenarioText(const std::string& name);

}  // namespace mapless::sim
