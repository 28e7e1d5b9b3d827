// One method on one generated world (sim/generator.h), judged as a robot owner would judge it:
// did it arrive, did it touch anything, did it stop, and was there a reason to stop. The runs are
// the suites' own (RepeatOnSimulator, RunEigenspaceFollow, RunPotential), observed frame by frame.
//
// - funnel: the world's route taught with keyframes, repeated with the sloped funnel lane and the
//   obstacle watch (stop), 10% motion noise, image noise, a perturbed start.
// - eigenspace: the route taught as route images, followed with the default follower and its
//   watch, 10% motion noise.
// - potential: the visual potential to the world's destination (the farthest taught place seen in
//   a straight line from the start), with the papers' downward-looking camera (90 degrees, 1 m
//   high, 40 degrees down) instead of the world's level one, 10% motion noise, image noise.
//
// A stop is a run of frames in which the method held the robot and said why. It is a stop before
// a real obstacle when an object put on the path after the teach stood within
// `obstacle_near_m` of the robot's footprint meanwhile, and a false stop otherwise. On a world
// with an object on the path, the funnel repeat and the follower succeed by stopping before it
// (the run then ends after max_blocked_s with the stop's reason) or by going round it and
// arriving; the potential by reaching its destination.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "mapless/sim/scenario.h"

namespace mapless::eval {

struct GeneratedRunOptions {
  std::string method = "funnel";  // funnel, eigenspace, potential
  std::uint64_t seed = 1;         // noise and start perturbation
  double max_blocked_s = 30.0;    // a stop that does not clear ends the run after this long
  double obstacle_near_m = 1.5;   // a stop with an added object this near is before an obstacle
  bool watch = true;              // the obstacle watch (funnel, eigenspace); false: the papers'
  void Validate() const;
};

struct GeneratedStop {
  double start_s = 0.0;
  double duration_s = 0.0;
  std::string reason;  // the method's words on the stop's first frame
  bool at_obstacle = false;
};

struct GeneratedWorldResult {
  std::string world;  // the scenario's name
  std::string kind;   // its labels
  bool feasible = true;
  bool obstacle = false;  // an object was put on the path after the teach
  bool success = false;
  bool arrived = false;  // completed the route or reached the destination
  bool collided = false;
  bool stopped_at_obstacle = false;  // a stop before the added object, no collision
  bool no_answer = false;            // ended by the simulator's timeout, not by the method
  std::string end_reason;            // why the run ended (the method's or the loop's words)
  double final_error_m = 0.0;        // to the route's end or the destination
  double duration_s = 0.0;
  std::vector<GeneratedStop> stops;
  std::vector<Pose2> reference_path;  // the taught path (or start and destination)
  std::vector<Pose2> path;            // the run's ground truth, one per frame
  // The stops that were false, and the longest of them (s).
  int false_stops() const;
  double longest_false_stop_s() const;
};

// The scenario as the potential sees it: the papers' downward-looking camera.
sim::Scenario PotentialWorld(sim::Scenario scenario);

// Runs options.method on the scenario. A world whose teach drive cannot be completed is a failure
// whose end_reason says so.
GeneratedWorldResult RunGeneratedWorld(const sim::Scenario& scenario,
                                       const GeneratedRunOptions& options);

// A stop reason with its numbers taken out, for the histogram ("obstacle ahead: #% of ...").
std::string StopKind(const std::string& reason);

}  // namespace mapless::eval
