#include "mapless/run/learn.h"

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

}  // namespace mapless::run
