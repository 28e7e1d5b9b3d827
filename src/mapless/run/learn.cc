#include "mapless/run/learn.h"

#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <set>
#include <thread>

#include "mapless/core/check.h"
#include "mapless/fleet/client.h"
#include "mapless/fleet/route_log.h"
#include "mapless/io/output_dir.h"
#include "mapless/route/route_store.h"

namespace mapless::run {

void CheckLearnable(const std::string& dir, bool complete, int visits,
                    const std::string& views_folder, const std::string& command) {
  namespace fs = std::filesystem;
  MAPLESS_CHECK(complete, command << ": " << dir
                                  << " is an interrupted teach; views are learned into complete "
                                     "routes (teach it again)");
  MAPLESS_CHECK(visits < route::kMaxRouteVisits,
                command << ": " << dir << " has " << visits << " visits, the most a route counts");
  // The manifest is replaced (a new file renamed over it: the directory must be writable), view
  // files are written into the folder (created in the route when it is missing).
  std::vector<std::string> written = {dir};
  const fs::path folder = fs::path(dir) / views_folder;
  std::error_code ec;
  if (fs::exists(folder, ec)) written.push_back(folder.string());
  for (const std::string& d : written)
    MAPLESS_CHECK(::access(d.c_str(), W_OK | X_OK) == 0,
                  command << ": " << d << ": cannot be written (" << std::strerror(errno)
                          << "); the visit could not be saved");
}

std::string SaveVisit(const std::string& dir, const route::Route& route,
                      const std::vector<int>& used_views,
                      std::vector<navigation::LearnedView> learned,
                      const navigation::ExperienceOptions& options) {
  std::string keyframes;
  for (const auto& l : learned)
    keyframes += (keyframes.empty() ? "" : ", ") + std::to_string(l.keyframe);
  route::Route updated = route;
  const int added = navigation::ApplyVisit(&updated, used_views, std::move(learned), options);
  route::SaveViews(dir, &updated);
  std::size_t views = 0;
  for (const auto& kf : updated.keyframes) views += kf.views.size();
  return dir + ": visit " + std::to_string(updated.visits) + ", " + std::to_string(added) +
         " view" + (added == 1 ? "" : "s") + " learned" +
         (keyframes.empty() ? "" : " (keyframes " + keyframes + ")") + ", " +
         std::to_string(views) + " learned views in all";
}

std::string SaveAppearanceVisit(const std::string& dir, const route::StoredAppearanceRoute& route,
                                const std::vector<int>& used_views,
                                std::vector<navigation::LearnedAppearanceView> learned,
                                const navigation::AppearanceExperienceOptions& options) {
  std::string places;
  for (const auto& l : learned) places += (places.empty() ? "" : ", ") + std::to_string(l.place);
  route::StoredAppearanceRoute updated = route;
  const int added =
      navigation::ApplyAppearanceVisit(&updated, used_views, std::move(learned), options);
  route::SaveAppearanceViews(dir, &updated);
  return dir + ": visit " + std::to_string(updated.visits) + ", " + std::to_string(added) +
         " view" + (added == 1 ? "" : "s") + " learned" +
         (places.empty() ? "" : " (route images " + places + ")") + ", " +
         std::to_string(updated.views()) + " learned views in all";
}

std::string PruneRouteViews(const std::string& dir, int max_views) {
  const io::DirectoryLock lock(dir);
  if (std::filesystem::exists(std::filesystem::path(dir) / "appearance.json") &&
      !std::filesystem::exists(std::filesystem::path(dir) / "manifest.json")) {
    // An appearance route (follow --learn): its route images' learned views.
    route::StoredAppearanceRoute stored = route::LoadAppearanceRoute(dir);
    const int removed = navigation::PruneAppearanceViews(&stored, max_views);
    if (removed > 0) route::SaveAppearanceViews(dir, &stored);
    return dir + ": " + std::to_string(removed) + " learned view" + (removed == 1 ? "" : "s") +
           " pruned, " + std::to_string(stored.views()) + " left";
  }
  route::Route route = route::LoadRoute(dir);
  const int removed = navigation::PruneViews(&route, max_views);
  if (removed > 0) route::SaveViews(dir, &route);
  std::size_t left = 0;
  for (const auto& kf : route.keyframes) left += kf.views.size();
  return dir + ": " + std::to_string(removed) + " learned view" + (removed == 1 ? "" : "s") +
         " pruned, " + std::to_string(left) + " left";
}

std::string MergeRouteViews(const std::string& dir, const std::string& other, int max_views) {
  MAPLESS_CHECK(!std::filesystem::exists(other) || !std::filesystem::equivalent(dir, other),
                "route merge: " << other << " is the route itself");
  MAPLESS_CHECK(!std::filesystem::exists(std::filesystem::path(dir) / "appearance.json"),
                "route merge: " << dir
                                << " is an appearance route; merging its learned views is not "
                                   "supported (route info --views and route prune are)");
  const io::DirectoryLock lock(dir);
  const io::DirectoryLock other_lock(other);  // not while a repeat learns into it
  route::Route route = route::LoadRoute(dir);
  const int merged = navigation::MergeViews(&route, route::LoadRoute(other), max_views);
  if (merged > 0) route::SaveViews(dir, &route);  // nothing new: nothing written (idempotent)
  std::size_t views = 0;
  for (const auto& kf : route.keyframes) views += kf.views.size();
  return dir + ": " + std::to_string(merged) + " learned view" + (merged == 1 ? "" : "s") +
         " merged from " + other + ", " + std::to_string(views) + " in all";
}

std::string ShareLearnedViews(const fleet::RouteCopy& copy, fleet::FollowerClient& client,
                              const std::vector<navigation::LearnedView>& learned, double wait_s) {
  const std::shared_ptr<const route::Route> route = copy.FunnelRoute();
  if (learned.empty() || !route) return "learned no views to offer the leader";
  std::vector<fleet::Record> offers;
  for (const navigation::LearnedView& l : learned) {
    MAPLESS_CHECK(l.keyframe >= 0 && l.keyframe < static_cast<int>(route->keyframes.size()),
                  "ShareLearnedViews: keyframe " << l.keyframe);
    route::KeyframeView view;
    view.keypoints = l.features.keypoints;
    view.descriptors = l.features.descriptors;
    view.offset_px = l.offset_px;
    offers.push_back(
        fleet::ShareViewRecord(route->keyframes[static_cast<std::size_t>(l.keyframe)], view));
  }
  std::set<std::string> files;  // what comes back: the same view file (other views may come too)
  for (const fleet::Record& r : offers) files.insert(r.parts[1]);
  const std::uint64_t before = copy.next_sequence();
  const std::size_t n = offers.size();
  client.Share(std::move(offers));
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(wait_s);
  std::vector<std::uint64_t> back;
  while (true) {
    back.clear();
    for (const fleet::Record& r : copy.RecordsFrom(before, 1u << 16))
      if (r.type == fleet::RecordType::kView && files.count(r.parts[1])) back.push_back(r.sequence);
    if (back.size() >= n || std::chrono::steady_clock::now() >= end) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  std::string line = "offered " + std::to_string(n) + " view" + (n == 1 ? "" : "s") +
                     " to the leader; " + std::to_string(back.size()) + " in the route now";
  if (!back.empty())
    line += " (records " + std::to_string(back.front()) + "-" + std::to_string(back.back()) + ")";
  if (back.size() < n)
    line += "; the leader's log says why it took fewer (a leader without --take-views takes none)";
  return line;
}

}  // namespace mapless::run
