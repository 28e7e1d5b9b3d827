// The three runs of `mapless demo`, each on the built-in simulator and each giving its section of
// the report and its line of the results table.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "mapless/eval/teach_repeat.h"
#include "run_report.h"

namespace mapless::app {

struct DemoResult {
  RunSection section;
  std::vector<std::string> row;  // method, scenario, success, final error (m), detail
  bool success = false;
  std::string status;
};

// Teach & repeat with the sloped funnel lane: `taught` (already taught on `scenario`) repeated
// from a perturbed start with motion and image noise; decisions as JSON lines to `log_path`.
DemoResult DemoRepeat(const sim::Scenario& scenario, const eval::TaughtRoute& taught,
                      std::uint64_t seed, const std::string& log_path);
// The eigenspace follower on `scenario_name` while the leader is still teaching it.
DemoResult DemoEigenspace(const std::string& scenario_name, std::uint64_t seed);
// The visual potential to the scenario's first destination and home again.
DemoResult DemoPotential(const std::string& scenario_name, std::uint64_t seed);

}  // namespace mapless::app
