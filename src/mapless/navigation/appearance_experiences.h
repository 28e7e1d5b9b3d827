// Experiences for the appearance follower (issue 45; not in Payá et al.): a place of an
// appearance route (a route image) holds its taught image and up to max_views - 1 views learned
// on later follows. The eigenspace is built over all of them (taught images first, then the
// views), the Markov localization runs over places (a place is as near as its nearest view:
// localization::NearestPlaces), and where the route image ahead gives no sub-window fit the
// follower steers by that place's learned view nearest the current image, its shift chained to
// the taught image by the offset the route measured when it learned the view. The same idea as the
// funnel route's experiences (experiences.h), on the follower's quantities.
//
// When a follow learns (AppearanceFollowerOptions::learn): once per place, on the first frame its
// belief is on the place with at least learn_probability and it steers by the place ahead (not
// recovering, not carrying on: sure of the place), when the current
// image is further from every view of the place than the place's route image is from its nearest
// neighbour on the route, in the eigenspace (the appearance has moved: a nearest-projection
// observation could no longer tell the place from the next), and the sub-window fit against the
// nearest view gives the offset. The views are written into the route when the follow arrives
// (`mapless follow --learn`).
//
// Pure: routes and views in, routes out; where the route lives is the caller's.
#pragma once

#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "mapless/route/appearance_route.h"
#include "mapless/route/appearance_store.h"

namespace mapless::navigation {

struct AppearanceLeaderOptions;

struct AppearanceExperienceOptions {
  // Views per place, the taught image included; the learned view used least recently makes room.
  int max_views = 5;
  double learn_probability = 0.9;  // the belief's mass around the place: sure of the place
  // Learned when the nearest view is further than this times the distance from the place's route
  // image to its nearest neighbour's (in the eigenspace).
  double changed_ratio = 1.0;
  void Validate() const;
};

// A view one follow learned: the place, the 8-bit low-resolution image (as the route stores
// them), its offset (chained to the taught image) and why it was learned.
struct LearnedAppearanceView {
  int place = 0;
  cv::Mat low;
  double offset_px = 0.0;
  std::string why;
};

// One follow's visit of a stored route: route->visits + 1; the view each place was steered by
// (`used_views`: 0 the taught image, i + 1 learned view i, -1 none) marked used at it; the learned
// views added, the least recently useful learned view (then the oldest) making room when a place
// has max_views. Returns the number of views added.
int ApplyAppearanceVisit(route::StoredAppearanceRoute* route, const std::vector<int>& used_views,
                         std::vector<LearnedAppearanceView> learned,
                         const AppearanceExperienceOptions& options);

// Keeps at most max_views views per place (the taught image included), the least recently used
// learned views going first. Returns the number removed; throws InputError when max_views < 1.
int PruneAppearanceViews(route::StoredAppearanceRoute* route, int max_views);

// The follower's route from a stored one: the route images through the incremental PCA in order,
// then each image's learned views in order (so their columns follow the images'), complete when
// the stored route is. Throws InputError when the images are not the size `options` builds at.
std::shared_ptr<const route::AppearanceRoute> BuildStoredAppearanceRoute(
    const route::StoredAppearanceRoute& stored, const AppearanceLeaderOptions& options);

}  // namespace mapless::navigation
