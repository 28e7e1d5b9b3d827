// `mapless lead` (teach a route and serve it to followers), `mapless follow --connect` (follow a
// route a leader serves, while it is still being taught) and `mapless fleet keygen`.
#pragma once

#include <CLI/CLI.hpp>
#include <cstdint>
#include <string>
#include <vector>

#include "mapless/live/live_view.h"

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
  bool learn = false;       // funnel: offer the leader the views the repeat learned
  live::LiveArgs live;      // --live
};
void FollowConnected(const FollowConnectArgs& a);

void AddLeadCommand(CLI::App* app);
void AddFleetCommand(CLI::App* app);  // mapless fleet keygen

}  // namespace mapless::app
