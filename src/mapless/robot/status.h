// What a method decided on one frame, for people and tools: the status as one JSON object (the
// robot link's status topic, the commands' --log) and the debug image (the robot link's debug
// topic): the frame with the matched features and the funnel-lane slopes (repeat), the dominant
// plane and the control force (navigate), or the localization and sub-window fit (follow).
#pragma once

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "mapless/robot/method.h"

namespace mapless::robot {

// {"t_s", "method", "state", "status", "reason", "v_mps", "omega_radps", ...the method's own
// fields}. `frame` is the frame's number in the run.
nlohmann::json StatusJson(const char* method, int frame, const Observation& observation,
                          const Decision& decision);

// `text` in lines of the debug picture's font no wider than `max_width_px`, broken between words
// (a word wider than that is cut), at most `max_lines` (the last then ends in "...").
std::vector<std::string> WrapText(const std::string& text, int max_width_px, int max_lines);

// `v` with `digits` decimals, for the debug picture's text.
std::string FixedText(double v, int digits);

// A status for a stop that no frame decided (no camera, e-stop, interrupted).
nlohmann::json StopJson(const char* method, Timestamp t_ns, const std::string& reason);

// The debug picture: BGR, the frame's size (at least 320 wide: small frames are enlarged).
cv::Mat DebugImage(const Observation& observation, const Decision& decision);

}  // namespace mapless::robot
