// Evaluation suites that reproduce Section VII of Kassir et al. on the simulator: each entry is a
// scenario and a controller, repeated `runs` times with their own noise and start perturbation.
#pragma once

#include <limits>
#include <string>
#include <vector>

#include "mapless/eval/teach_repeat.h"

namespace mapless::eval {

struct SuiteEntry {
  std::string scenario;
  navigation::Controller controller = navigation::Controller::kSloped;
};

// "table1": the two 10 m paths of Table I, both controllers.
// "funnel-scenarios": the six scenarios of Section VII-A, the 30 m and 70 m paths, and the
// rotation in place, both controllers.
// "obstacles" (issue 21, not in the paper): routes with something new on them at repeat time,
// and one whose keyframes in a turn saw mostly a car that is gone at repeat time (keyframe
// recovery); the sloped controller.
std::vector<std::string> SuiteNames();
// The objects a scenario's repeat adds (its variant), with the times they leave at: for the
// obstacle figures (stops while one stood there, clearance to it).
sim::World ObjectsAddedAtRepeat(const sim::Scenario& scenario);
// The variant with every object it adds staying for the whole run (no leaves_s, no leave_s):
// `eval --on-obstacle avoid`.
sim::WorldVariant ObjectsStay(sim::WorldVariant variant);
std::vector<SuiteEntry> SuiteEntries(const std::string& suite);  // throws InputError if unknown

struct EntryResult {
  std::string scenario;
  std::string controller;
  int runs = 0;
  int successes = 0;
  double final_error_m_rms = 0.0;  // RMS over runs of the final distance to the taught end
  double final_error_m_std = 0.0;  // standard deviation of that distance over runs
  double final_error_m_max = 0.0;  // the largest (of runs that completed without collision)
  double lateral_rms_m = 0.0;      // RMS over all repeated poses of the distance to the taught path
  int collisions = 0;
  // The obstacle watch (navigation/obstacle_watch.h): runs in which it stopped the robot at
  // least once (on the table1 and funnel-scenarios suites every such stop is a false alarm), and
  // on scenarios whose repeat adds objects (the obstacles suite): runs that stopped while one
  // stood in the world, and the smallest clearance between the robot's footprint and an added
  // object while it stood there (over all runs; +inf without added objects).
  int obstacle_stops = 0;
  int stops_at_added_object = 0;
  int went_round = 0;  // runs that went round an obstacle at least once (--on-obstacle avoid)
  int learned = 0;     // with repeat.learn: views the runs learned into the route, in order
  double min_clearance_m = std::numeric_limits<double>::infinity();
  std::vector<std::string> failures;  // one status line per failed run
  // Ground truth for reports: the reference path (taught, or the leader's) and each run's path.
  std::vector<Pose2> reference_path;
  std::vector<std::vector<Pose2>> paths;
};

// Runs one entry: the route is taught once (clean), then repeated `runs` times with seeds
// seed, seed + 1, ... The repeat drives at the scenario's teach speed, capped at
// base.max_repeat_speed_mps but not below half the teach speed. `first_run` (if set) observes
// every frame of the first run (for reports). With base.repeat.learn the runs repeat one route
// in order, each learning into it for the next (`repeat --learn`).
EntryResult RunEntry(const sim::Scenario& scenario, const TaughtRoute& taught,
                     navigation::Controller controller, int runs, std::uint64_t seed,
                     const RepeatRunOptions& base, const RepeatObserver& first_run = {});

}  // namespace mapless::eval
