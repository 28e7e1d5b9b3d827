// Writing a route's learned views (issue 45; route_store.h: SaveViews). The view files first, each
// atomically and flushed, then the manifest that lists them, atomically: a kill at any moment
// leaves the route as it was before or as it is after, never a manifest naming a missing file.
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <vector>

#include "mapless/core/check.h"
#include "mapless/io/atomic_file.h"
#include "mapless/route/manifest_text.h"
#include "mapless/route/route_store.h"

namespace mapless::route {

bool IsViewFileName(const std::string& name, const std::string& extension) {
  const std::size_t dash = name.find("-visit-");
  const std::size_t dot = name.rfind('.');
  if (dash != 6 || dot == std::string::npos || dot < dash + 11 || name.substr(dot) != extension)
    return false;
  const auto digits = [&](std::size_t from, std::size_t to) {
    for (std::size_t i = from; i < to; ++i)
      if (name[i] < '0' || name[i] > '9') return false;
    return true;
  };
  return digits(0, 6) && digits(dash + 7, dot);
}

std::string ViewFileName(int keyframe, int learned_at) {
  char name[64];
  std::snprintf(name, sizeof(name), "-visit-%04d.yml", learned_at);
  return KeyframeFileStem(keyframe) + name;
}

void SaveViews(const std::string& dir, Route* route) {
  MAPLESS_CHECK(route->visits >= 0, "SaveViews: visits = " << route->visits);
  std::vector<std::string> written;
  std::set<std::string> listed;
  for (Keyframe& kf : route->keyframes) {
    MAPLESS_CHECK(kf.views.size() <= static_cast<std::size_t>(kMaxViewsPerKeyframe),
                  "SaveViews: keyframe " << kf.index << " has " << kf.views.size() << " views");
    for (KeyframeView& view : kf.views) {
      if (view.file.empty()) {
        Keyframe file;
        file.index = kf.index;
        file.t_ns = kf.t_ns;
        file.keypoints = view.keypoints;
        file.descriptors = view.descriptors;
        view.file = ViewFileName(kf.index, view.learned_at);
        const std::string path = (std::filesystem::path(dir) / view.file).string();
        io::WriteFileAtomic(path, SerializeKeyframe(file), false);
        written.push_back(path);
      }
      listed.insert(view.file);
    }
  }
  io::SyncFiles(written);
  nlohmann::json head;
  head["format"] = "mapless-route";
  head["version"] = kRouteViewsFormatVersion;
  head["visits"] = route->visits;
  head["detector"] = route->detector;
  head["image_width"] = route->image_width;
  head["image_height"] = route->image_height;
  head["complete"] = route->complete;
  std::vector<std::string> entries;
  for (const Keyframe& kf : route->keyframes) {
    nlohmann::json entry = {{"index", kf.index},
                            {"t_s", ToSeconds(kf.t_ns)},
                            {"data", KeyframeFileStem(kf.index) + ".yml"},
                            {"thumbnail", KeyframeFileStem(kf.index) + ".png"}};
    nlohmann::json views = nlohmann::json::array();
    for (const KeyframeView& v : kf.views) {
      views.push_back({{"data", v.file},
                       {"offset_px", v.offset_px},
                       {"learned_at", v.learned_at},
                       {"last_used", v.last_used}});
    }
    entry["views"] = views;
    entries.push_back(EntryText(entry));
  }
  io::WriteFileAtomic((std::filesystem::path(dir) / "manifest.json").string(),
                      ManifestText(head, "keyframes", entries));
  // Pruned views: their files, now listed nowhere.
  const std::filesystem::path keyframes = std::filesystem::path(dir) / "keyframes";
  for (const auto& file : std::filesystem::directory_iterator(keyframes)) {
    const std::string name = "keyframes/" + file.path().filename().string();
    if (IsViewFileName(file.path().filename().string(), ".yml") && file.is_regular_file() &&
        !file.is_symlink() && listed.count(name) == 0) {
      std::error_code ignored;
      std::filesystem::remove(file.path(), ignored);
    }
  }
}

}  // namespace mapless::route
