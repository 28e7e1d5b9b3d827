// The decision log of runs that an evaluation function drives (eval::RepeatOnSimulator,
// eval::RunPotential take a link wrapper): every decision sent to the link, in the one format of
// run_method.h (robot/status.h's JSON), with the true pose where the link knows it.
#pragma once

#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "mapless/robot/link.h"

namespace mapless::run {

using JsonSink = std::function<void(const nlohmann::json&)>;

// A wrapper that logs to `log` around the link `then` makes of the inner one (e.g. a recording;
// empty: none). The decision on which a run ends by a collision or an evaluation's goal is not
// sent to the link, so it is not in this log.
robot::LinkWrapper LogDecisions(std::string method, JsonSink log, robot::LinkWrapper then = {});

// The true pose ("x_m", "y_m", "theta_rad"), when there is one, added to a decision's JSON.
void AddTruth(const std::optional<Pose2>& truth, nlohmann::json* j);

}  // namespace mapless::run
