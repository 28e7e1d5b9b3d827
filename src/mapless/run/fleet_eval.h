// `mapless eval fleet`: one leader and N followers as separate processes of this program on
// loopback, on the simulator, with the faults asked for (the leader or a follower killed and
// started again, a follower's link cut for a while); then every follower's summary and whether its
// copy of the route is the leader's, byte for byte.
#pragma once

#include <cstdint>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>

namespace mapless::run {

struct FleetEvalOptions {
  int followers = 3;
  std::string method = "funnel";
  std::string scenario;  // default: table1_almost_straight (funnel), office_aliasing (eigenspace)
  double rate = 4.0;     // simulated seconds per wall-clock second, every process
  double start_after_s = 3.0;       // wall clock: followers start this long after the leader
  double kill_leader_at_s = 0.0;    // > 0: SIGKILL the leader then, and start it again
  double kill_follower_at_s = 0.0;  // > 0: SIGKILL follower 1 then, and start it again
  double link_down_at_s = 0.0;      // > 0: the last follower's link (a relay) goes down then ...
  double link_down_for_s = 10.0;    // ... for this long
  bool curve = false;               // CURVE keys for everyone
  std::string keep;                 // work directory to keep (default: a temporary one, removed)
  std::uint64_t seed = 1;
  std::string program = "/proc/self/exe";  // the mapless the processes run
  // Called every 50 ms while the processes run (a check for the user's interrupt, which may
  // throw: the processes are then stopped and the exception goes on), and with each fault.
  std::function<void()> each_tick;
  std::function<void(const std::string&)> say;
};

struct FleetEvalOutput {
  nlohmann::json json;  // {"suite": "fleet", ..., "results": [one per follower], "ok"}
  std::string table;
  bool ok = false;  // every follower completed, with a copy identical to the leader's route
};

FleetEvalOutput RunFleetEval(const FleetEvalOptions& options);

}  // namespace mapless::run
