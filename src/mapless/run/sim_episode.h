// The simulator as a source of a method's run (closed loop): where the robot starts, how long the
// run may take and what counts as arriving are the evaluation suites' (eval/), so that a command's
// run on sim:SCENARIO is one run of the suite. The simulation's robot is a robot link like any
// other (robot/sim_link.h), optionally in step with the wall clock (followers of a live leader).
#pragma once

#include <cstdint>
#include <memory>
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <vector>

#include "mapless/eval/teach_repeat.h"
#include "mapless/fleet/route_log.h"
#include "mapless/robot/sim_link.h"
#include "mapless/sim/simulation.h"

namespace mapless::run {

struct SimEpisode {
  eval::SimSetup setup;
  double timeout_s = 0.0;
  std::vector<Pose2> taught;  // the scenario's taught path (driven, not rendered)
  double taught_duration_s = 0.0;
  double tolerance_m = 0.0;  // success: the run ends this close to the taught path's end
};

// The episode of following a route of `kind` on the scenario; `live_leader`: the route is still
// being taught, so the run may take twice as long.
SimEpisode FollowEpisode(const sim::Scenario& scenario, fleet::RouteKind kind, std::uint64_t seed,
                         double motion_noise, bool live_leader);

// The simulator set up like a run of `like` (`mapless sim serve --like`): teach (the teach start,
// no noise), repeat, navigate or follow (as those commands' runs on the simulator, seeded). Throws
// InputError for another.
eval::SimSetup SimSetupLike(const sim::Scenario& scenario, const std::string& like,
                            std::uint64_t seed, double motion_noise, double image_noise);

// The episode's simulation with its robot as a link. `rate`: simulated seconds per wall-clock
// second (0: as fast as it can).
class SimRun {
 public:
  SimRun(const sim::Scenario& scenario, SimEpisode episode, double rate = 0.0);
  ~SimRun();
  robot::RobotLink& link();
  const Pose2& truth() const;
  bool collided() const;
  double error_at_end_m() const;  // from the true pose to the taught path's end
  bool succeeded(bool method_finished) const;
  // Adds the true pose ("x_m", "y_m", "theta_rad") to a decision's JSON.
  void AddTruth(nlohmann::json* j) const;
  const SimEpisode& episode() const { return episode_; }

 private:
  class Paced;
  SimEpisode episode_;
  sim::Simulation sim_;
  int robot_;
  robot::SimLink link_;
  std::unique_ptr<Paced> paced_;
};

// Keeps a simulation in step with the wall clock: simulated time runs `rate` times as fast
// (0: no pacing).
class Pacer {
 public:
  explicit Pacer(double rate) : rate_(rate) {}
  void At(Timestamp sim_ns);

 private:
  double rate_;
  bool started_ = false;
  std::int64_t wall0_ns_ = 0;
  Timestamp sim0_ = 0;
};

}  // namespace mapless::run
