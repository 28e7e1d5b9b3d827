#include "mapless/run/learn.h"

#include <filesystem>

#include "mapless/core/check.h"
#include "mapless/io/output_dir.h"
#include "mapless/route/route_store.h"

namespace mapless::run {

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

std::string PruneRouteViews(const std::string& dir, int max_views) {
  const io::DirectoryLock lock(dir);
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
  const io::DirectoryLock lock(dir);
  const io::DirectoryLock other_lock(other);  // not while a repeat learns into it
  route::Route route = route::LoadRoute(dir);
  const int merged = navigation::MergeViews(&route, route::LoadRoute(other), max_views);
  route::SaveViews(dir, &route);
  std::size_t views = 0;
  for (const auto& kf : route.keyframes) views += kf.views.size();
  return dir + ": " + std::to_string(merged) + " learned view" + (merged == 1 ? "" : "s") +
         " merged from " + other + ", " + std::to_string(views) + " in all";
}

}  // namespace mapless::run
