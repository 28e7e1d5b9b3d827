// `mapless route info`: a route loaded (every file checked) and described, for people (one line)
// and for scripts (one JSON object).
#pragma once

#include <nlohmann/json.hpp>
#include <string>

namespace mapless::run {

// A keyframe route: kind "keyframes", keyframes, complete, detector, image_width, image_height,
// keypoints, visits and learned_views (repeat --learn), duration_s (first to last keyframe). An
// appearance route (teach --method eigenspace):
// kind "appearance", images, complete, image_width, image_height, low_width, low_height, length_m.
// Throws InputError for a route that does not load.
nlohmann::json RouteInfo(const std::string& dir);

// The same as one line: "DIR: 12 keyframes (complete), orb features, 320x240, 41.3 s".
std::string RouteInfoLine(const std::string& dir, const nlohmann::json& info);

}  // namespace mapless::run
