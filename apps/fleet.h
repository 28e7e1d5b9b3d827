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
};
void FollowConnected(const FollowConnectArgs& a);

void AddLeadCommand(CLI::App* app);
void AddFleetCommand(CLI::App* app);      // mapless fleet keygen
void AddEvalFleet(CLI::App* eval);        // mapless eval fleet

}  // namespace mapless::app
