#include "mapless/run/route_info.h"

#include <filesystem>

#include "mapless/route/appearance_store.h"
#include "mapless/route/route_store.h"
#include "mapless/run/text.h"

namespace mapless::run {

namespace {

nlohmann::json ViewsOf(const route::Route& route) {
  nlohmann::json all = nlohmann::json::array();
  for (const auto& kf : route.keyframes) {
    nlohmann::json views = nlohmann::json::array();
    for (const auto& v : kf.views) {
      views.push_back({{"learned_at", v.learned_at},
                       {"last_used", v.last_used},
                       {"offset_px", v.offset_px},
                       {"features", v.keypoints.size()}});
    }
    all.push_back(views);
  }
  return all;
}

std::string ViewLines(const nlohmann::json& views, const char* what) {
  std::string out;
  for (std::size_t k = 0; k < views.size(); ++k) {
    if (views[k].empty()) continue;
    out += Format("\n  %s %zu: taught view + %zu learned:", what, k, views[k].size());
    for (const auto& v : views[k]) {
      out += Format(" visit %d (used at %d, %+.1f px", v["learned_at"].get<int>(),
                    v["last_used"].get<int>(), v["offset_px"].get<double>());
      out += v.contains("features") ? Format(", %zu features)", v["features"].get<std::size_t>())
                                    : std::string(")");
    }
  }
  return out;
}

}  // namespace

nlohmann::json RouteInfo(const std::string& dir, bool list_views) {
  const std::filesystem::path path(dir);
  nlohmann::json j;
  if (std::filesystem::exists(path / "appearance.json") &&
      !std::filesystem::exists(path / "manifest.json")) {
    const route::StoredAppearanceRoute a = route::LoadAppearanceRoute(dir);
    j = {{"kind", "appearance"},
         {"images", a.images.size()},
         {"complete", a.complete},
         {"image_width", a.image_width},
         {"image_height", a.image_height},
         {"low_width", a.low_width},
         {"low_height", a.low_height},
         {"length_m", a.images.empty() ? 0.0 : a.images.back().distance_m},
         {"visits", a.visits},
         {"learned_views", a.views()}};
    if (list_views) {
      nlohmann::json all = nlohmann::json::array();
      for (const auto& image : a.images) {
        nlohmann::json views = nlohmann::json::array();
        for (const auto& v : image.views) {
          views.push_back({{"learned_at", v.learned_at},
                           {"last_used", v.last_used},
                           {"offset_px", v.offset_px}});
        }
        all.push_back(views);
      }
      j["views"] = all;
    }
    return j;
  }
  const route::Route route = route::LoadRoute(dir);
  std::size_t keypoints = 0;
  std::size_t views = 0;
  for (const auto& kf : route.keyframes) {
    keypoints += kf.keypoints.size();
    views += kf.views.size();
  }
  j = {{"kind", "keyframes"},
       {"keyframes", route.keyframes.size()},
       {"complete", route.complete},
       {"detector", route.detector},
       {"image_width", route.image_width},
       {"image_height", route.image_height},
       {"keypoints", keypoints},
       {"visits", route.visits},
       {"learned_views", views}};
  // From the first keyframe to the last: a robot's keyframes carry the ROS clock's time.
  j["duration_s"] = route.keyframes.empty()
                        ? 0.0
                        : ToSeconds(route.keyframes.back().t_ns - route.keyframes.front().t_ns);
  if (list_views) j["views"] = ViewsOf(route);
  return j;
}

std::string RouteInfoLine(const std::string& dir, const nlohmann::json& j) {
  const char* state = j["complete"].get<bool>() ? "complete" : "INTERRUPTED teach";
  if (j["kind"] == "appearance") {
    const int visits = j["visits"].get<int>();
    const std::string learned = visits == 0 ? ""
                                            : Format(", %d learned views over %d follows",
                                                     j["learned_views"].get<int>(), visits);
    return Format("%s: appearance route of %zu images (%s), %dx%d camera, %dx%d stored, %.1f m%s",
                  dir.c_str(), j["images"].get<std::size_t>(), state, j["image_width"].get<int>(),
                  j["image_height"].get<int>(), j["low_width"].get<int>(),
                  j["low_height"].get<int>(), j["length_m"].get<double>(), learned.c_str()) +
           (j.contains("views") ? ViewLines(j["views"], "route image") : "");
  }
  const int visits = j["visits"].get<int>();
  const std::string learned = visits == 0 ? ""
                                          : Format(", %zu learned views over %d repeats",
                                                   j["learned_views"].get<std::size_t>(), visits);
  return Format("%s: %zu keyframes (%s), %s features, %dx%d, %.1f s%s", dir.c_str(),
                j["keyframes"].get<std::size_t>(), state, j["detector"].get<std::string>().c_str(),
                j["image_width"].get<int>(), j["image_height"].get<int>(),
                j["duration_s"].get<double>(), learned.c_str()) +
         (j.contains("views") ? ViewLines(j["views"], "keyframe") : "");
}

}  // namespace mapless::run
