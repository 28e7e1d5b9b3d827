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
// Throws InputError for a route that does not load. With `views` (`route info --views`), a
// keyframe route also lists each keyframe's learned views: "views", one array per keyframe of
// {learned_at, last_used, offset_px, features}.
nlohmann::json RouteInfo(const std::string& dir, bool views = false);

// The same as one line: "DIR: 12 keyframes (complete), orb features, 320x240, 41.3 s"; with the
// views listed, one more line per keyframe that has learned views ("  keyframe 4: taught view +
// 2 learned: visit 3 (used at 5, +12.5 px, 402 features), ...").
std::string RouteInfoLine(const std::string& dir, const nlohmann::json& info);

}  // namespace mapless::run
