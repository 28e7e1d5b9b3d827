// `mapless lead` (teach a route and serve it to followers), `mapless follow --connect` (follow a
// route a leader serves, while it is still being taught), `mapless fleet keygen`, and
// `mapless eval fleet` (one leader and N followers as separate processes on loopback).
#pragma once

#include <CLI/CLI.hpp>
#include <cstdint>
#include <string>
#include <vector>

namespace mapless::app {

struct FollowConnectArgs {
  std::string connect;
  std::string route;  // the local copy
  std::string source;
  std::string robot;
  std::string log;
  std::string summary;  // simulator: a JSON summary of the run (eval fleet)
  std::string curve_key;
  std::string curve_leader;
  double rate = 1.0;  // simulator: simulated seconds per wall-clock second
  std::uint64_t seed = 1;
  double motion_noise = 0.1;
  std::string on_obstacle;  // the obstacle watch: stop, off, or empty (the robot file's, else stop)
  double carry_on_m = 6.0;  // carrying on where the route no longer matches (0: off)
};
void FollowConnected(const FollowConnectArgs& a);

void AddLeadCommand(CLI::App* app);
void AddFleetCommand(CLI::App* app);  // mapless fleet keygen

// `mapless eval fleet`: one leader and N followers as separate processes of this program on
// loopback, on the simulator, with the faults asked for.
struct FleetEvalArgs {
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
};
void AddFleetEvalOptions(CLI::App* eval, FleetEvalArgs* args);
// Prints the table (stderr with json) and the JSON; throws RunFailed when a follower did not
// complete, a copy differs from the leader's route, or records are missing.
void RunFleetEval(const FleetEvalArgs& args, bool json);

}  // namespace mapless::app
