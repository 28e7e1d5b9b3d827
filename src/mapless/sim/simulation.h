// A running simulation: one world, one or more differential-drive robots each with its own camera,
// stepped at a fixed physics rate. Robots see each other (each is drawn as a textured cylinder in
// the others' cameras) and a collision with an obstacle, a wall or another robot is an event that
// the run reports. No threads, no clocks, no files: time advances only through Advance().
#pragma once

#include <functional>
#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "mapless/sim/renderer.h"
#include "mapless/sim/robot.h"
#include "mapless/sim/scenario.h"

namespace mapless::sim {

struct SimulationOptions {
  double physics_dt_s = 0.01;  // integration step
  double robot_body_height_m = 0.5;
  RenderOptions render;
  void Validate() const;
};

struct Collision {
  int robot = -1;
  Timestamp t_ns = 0;
  Pose2 pose;
  std::string with;  // "obstacle" or "robot N"
};

class Simulation {
 public:
  Simulation(const World& world, CameraSpec camera, SimulationOptions options, std::uint64_t seed);

  // Adds a robot; returns its index. Each robot has its own noise stream derived from the seed.
  int AddRobot(const Pose2& start, const RobotOptions& options);
  int robot_count() const { return static_cast<int>(robots_.size()); }
  const DiffDriveRobot& robot(int i) const { return robots_.at(static_cast<std::size_t>(i)); }

  void SetCommand(int robot, const Twist2& command);
  // Puts a robot at a pose, at rest (clears a collision stop).
  void PlaceRobot(int robot, const Pose2& pose);
  // Advances every robot by dt (rounded to whole physics steps); records collisions. A robot that
  // collided stops and stays where it hit. Objects appear and leave at their times (WorldObject::
  // appears_s, leaves_s), checked at every physics step.
  void Advance(double dt_s);
  Timestamp now_ns() const { return t_ns_; }

  // The image robot i's camera sees now, with the camera's image effects applied (their noise
  // stream is derived from the seed, the robot and that robot's frame count).
  cv::Mat Render(int robot);
  // The same without image effects and without advancing the frame count.
  cv::Mat RenderClean(int robot) const;

  const std::vector<Collision>& collisions() const { return collisions_; }
  bool collided(int robot) const;
  // The world now: the objects present at this time.
  const World& world() const { return world_; }
  const CameraSpec& camera() const { return camera_; }
  // The renderer; its textures are generated on first use (drives that never render skip that).
  const Renderer& renderer() const;

 private:
  std::vector<Surface> OtherRobots(int robot) const;
  void CheckCollisions();
  void UpdateTimedObjects();

  World all_objects_;              // as given, with every object's times
  std::vector<double> changes_s_;  // when an object appears or leaves
  std::size_t next_change_ = 0;
  World world_;
  CameraSpec camera_;
  SimulationOptions options_;
  std::uint64_t seed_;
  mutable std::unique_ptr<Renderer> renderer_;
  std::vector<DiffDriveRobot> robots_;
  std::vector<std::uint64_t> frames_;
  std::vector<bool> stopped_;
  std::vector<Collision> collisions_;
  std::vector<std::shared_ptr<const Texture>> body_textures_;
  Timestamp t_ns_ = 0;
};

// The teach phase on the simulator: the scripted driver drives the scenario's taught path and each
// camera frame is handed to `on_frame` (which may write it out).
struct DriveFrame {
  int index = 0;
  Timestamp t_ns = 0;
  Pose2 truth;
  Pose2 odometry;
  cv::Mat image;
};

struct DriveOptions {
  std::uint64_t seed = 1;
  double timeout_factor = 3.0;  // give up after this many times the nominal path duration
  bool stop_on_collision = true;
  bool render_frames = true;  // false: frames carry no image (fast, for path-only checks)
  // Frames for which this returns true carry no image (a leader resuming an interrupted teach
  // drives up to where it stopped without rendering).
  std::function<bool(const DriveFrame&)> skip_render;
  SimulationOptions sim;
  void Validate() const;
};

struct DriveSummary {
  int frames = 0;
  double duration_s = 0.0;
  double distance_m = 0.0;
  bool completed = false;  // the driver reached the end of the path
  bool collided = false;
  std::string status;  // "completed", "collision at ...", "timeout after ..."
};

// Parses a run configuration (config/default.yaml: render, simulation, drive); errors name `name`,
// the line and the field. Fuzzed by fuzz/fuzz_config.cc.
DriveOptions ParseDriveOptions(const std::string& yaml_text, const std::string& name);

DriveSummary DriveTaughtPath(const Scenario& scenario, const DriveOptions& options,
                             const std::function<void(const DriveFrame&)>& on_frame);

// `count` poses spread evenly along a scenario's taught path (the ground truth of a drive without
// noise, sampled every 0.1 s): typical views for benches and tests.
std::vector<Pose2> PosesAlongTaughtPath(const Scenario& scenario, int count);

}  // namespace mapless::sim
