// The three runs of `mapless demo`, each on the built-in simulator and each giving its section of
// the report and its line of the results table.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "mapless/eval/teach_repeat.h"
#include "mapless/run/decision_log.h"
#include "mapless/run/report.h"

namespace mapless::run {

struct DemoResult {
  RunSection section;
  std::vector<std::string> row;  // method, scenario, success, final error (m), detail
  bool success = false;
  std::string status;
};

// Each run calls `each_frame` once per frame (the command's check for an interrupt, which throws).
// Teach & repeat with the sloped funnel lane: `taught` (already taught on `scenario`) repeated
// from a perturbed start with motion and image noise; its decisions to `log` (decision_log.h).
DemoResult DemoRepeat(const sim::Scenario& scenario, const eval::TaughtRoute& taught,
                      std::uint64_t seed, const JsonSink& log,
                      const std::function<void()>& each_frame);
// The eigenspace follower on `scenario_name` while the leader is still teaching it.
DemoResult DemoEigenspace(const std::string& scenario_name, std::uint64_t seed,
                          const std::function<void()>& each_frame);
// The visual potential to the scenario's first destination and home again.
DemoResult DemoPotential(const std::string& scenario_name, std::uint64_t seed,
                         const std::function<void()>& each_frame);

}  // namespace mapless::run
