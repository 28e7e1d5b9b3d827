#include "mapless/navigation/appearance_experiences.h"

#include <algorithm>

#include "mapless/core/check.h"
#include "mapless/navigation/appearance.h"
#include "mapless/route/route.h"

namespace mapless::navigation {
namespace {

// Removes learned views of `image` until it has at most max_views - 1: the one used least
// recently, then the oldest, first.
int MakeRoom(route::StoredAppearanceImage* image, int max_views) {
  int removed = 0;
  while (static_cast<int>(image->views.size()) > std::max(0, max_views - 1)) {
    const auto victim = std::min_element(
        image->views.begin(), image->views.end(), [](const auto& a, const auto& b) {
          return a.last_used != b.last_used ? a.last_used < b.last_used
                                            : a.learned_at < b.learned_at;
        });
    image->views.erase(victim);
    ++removed;
  }
  return removed;
}

}  // namespace

void AppearanceExperienceOptions::Validate() const {
  MAPLESS_CHECK(max_views >= 1 && max_views <= route::kMaxAppearanceViewsPerImage,
                "AppearanceExperienceOptions.max_views = " << max_views << "; must be in [1, "
                                                           << route::kMaxAppearanceViewsPerImage
                                                           << "]");
  MAPLESS_CHECK(learn_probability >= 0.0 && learn_probability <= 1.0,
                "AppearanceExperienceOptions.learn_probability = " << learn_probability
                                                                   << "; must be in [0, 1]");
  MAPLESS_CHECK(changed_ratio >= 0.0, "AppearanceExperienceOptions.changed_ratio = "
                                          << changed_ratio << "; must be >= 0");
}

int ApplyAppearanceVisit(route::StoredAppearanceRoute* route, const std::vector<int>& used_views,
                         std::vector<LearnedAppearanceView> learned,
                         const AppearanceExperienceOptions& options) {
  options.Validate();
  MAPLESS_CHECK(route->visits < route::kMaxRouteVisits,
                "the route has " << route->visits << " visits, the most it counts");
  const int visit = ++route->visits;
  const int n = static_cast<int>(route->images.size());
  for (int p = 0; p < n && p < static_cast<int>(used_views.size()); ++p) {
    const int used = used_views[static_cast<std::size_t>(p)];
    auto& views = route->images[static_cast<std::size_t>(p)].views;
    if (used >= 1 && used <= static_cast<int>(views.size()))
      views[static_cast<std::size_t>(used - 1)].last_used = visit;
  }
  int added = 0;
  for (LearnedAppearanceView& l : learned) {
    MAPLESS_CHECK(l.place >= 0 && l.place < n, "ApplyAppearanceVisit: no route image " << l.place);
    route::StoredAppearanceImage& image = route->images[static_cast<std::size_t>(l.place)];
    if (options.max_views <= 1) continue;
    bool learned_now = false;
    for (const auto& v : image.views) learned_now = learned_now || v.learned_at == visit;
    if (learned_now) continue;  // one view of a place a visit
    MakeRoom(&image, options.max_views - 1);
    route::StoredAppearanceView view;
    view.low = std::move(l.low);
    view.offset_px = l.offset_px;
    view.learned_at = visit;
    view.last_used = visit;
    image.views.push_back(std::move(view));
    ++added;
  }
  return added;
}

int PruneAppearanceViews(route::StoredAppearanceRoute* route, int max_views) {
  MAPLESS_CHECK(max_views >= 1, "--max-views " << max_views << ": must be at least 1");
  int removed = 0;
  for (route::StoredAppearanceImage& image : route->images) removed += MakeRoom(&image, max_views);
  return removed;
}

std::shared_ptr<const route::AppearanceRoute> BuildStoredAppearanceRoute(
    const route::StoredAppearanceRoute& stored, const AppearanceLeaderOptions& options) {
  MAPLESS_CHECK(
      stored.low_width == options.image.width && stored.low_height == options.image.height,
      "the route images are " << stored.low_width << "x" << stored.low_height
                              << ", this mapless builds its model at " << options.image.width << "x"
                              << options.image.height);
  AppearanceLeader leader(options);
  for (const route::StoredAppearanceImage& image : stored.images)
    leader.AddStored(image.low, image.distance_m, image.odometry);
  for (std::size_t p = 0; p < stored.images.size(); ++p)
    for (const route::StoredAppearanceView& view : stored.images[p].views)
      leader.AddStoredView(static_cast<int>(p), view.low, view.offset_px);
  if (stored.complete) leader.Finish();
  return leader.Snapshot();
}

}  // namespace mapless::navigation
