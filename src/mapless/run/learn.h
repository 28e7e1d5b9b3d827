// `mapless repeat --learn` (issue 45): what one repeat learned, written into its route.
#pragma once

#include <string>
#include <vector>

#include "mapless/navigation/appearance_experiences.h"
#include "mapless/navigation/experiences.h"
#include "mapless/route/appearance_store.h"
#include "mapless/route/route.h"

namespace mapless::fleet {
class RouteCopy;
class FollowerClient;
}  // namespace mapless::fleet

namespace mapless::run {

// Applies the visit (navigation::ApplyVisit) to a copy of `route` and writes it into `dir`
// (route::SaveViews; the caller holds the directory's lock). Returns one line for the log: "route:
// visit 3, 2 views learned (keyframes 4, 5), 7 views in all".
std::string SaveVisit(const std::string& dir, const route::Route& route,
                      const std::vector<int>& used_views,
                      std::vector<navigation::LearnedView> learned,
                      const navigation::ExperienceOptions& options);

// `mapless follow --learn` (issue 45): applies the follow's visit (navigation::
// ApplyAppearanceVisit) to a copy of the stored appearance route and writes its views into `dir`
// (route::SaveAppearanceViews; the caller holds the lock). Returns one line for the log: "route:
// visit 3, 2 views learned (route images 4, 5), 7 learned views in all".
std::string SaveAppearanceVisit(const std::string& dir, const route::StoredAppearanceRoute& route,
                                const std::vector<int>& used_views,
                                std::vector<navigation::LearnedAppearanceView> learned,
                                const navigation::AppearanceExperienceOptions& options);

// Before a run that learns into the route at `dir` (repeat --learn, follow --learn): the route must
// be complete (an interrupted teach is not learned into), below kMaxRouteVisits, and its directory
// and the folder its view files go to (`views_folder`: "keyframes" or "views") writable, so that
// the run does not drive the whole route and then fail to save. Throws InputError naming `command`
// and what is wrong.
void CheckLearnable(const std::string& dir, bool complete, int visits,
                    const std::string& views_folder, const std::string& command);

// `mapless route prune ROUTE --max-views N`: locks the route directory, keeps at most N views per
// keyframe (navigation::PruneViews) and writes what changed (route::SaveViews: the manifest, then
// the pruned files removed). Returns one line: "ROUTE: 3 learned views pruned, 12 left".
std::string PruneRouteViews(const std::string& dir, int max_views);

// `mapless route merge ROUTE OTHER --max-views N`: the views OTHER learned, merged into ROUTE
// (navigation::MergeViews; both directories locked, OTHER only read). Returns one line:
// "ROUTE: 4 learned views merged from OTHER, 9 in all".
std::string MergeRouteViews(const std::string& dir, const std::string& other, int max_views);

// `follow --connect --learn` (issue 45): offers the leader the views a follower's repeat learned
// (fleet::ShareViewRecord) and waits up to wait_s for the leader to take them into the route and
// for them to come back to `copy` as records. Returns one line: "offered 2 views to the leader;
// 2 are in the route now (records 21-22)" (fewer when the leader took fewer: its log says why).
std::string ShareLearnedViews(const fleet::RouteCopy& copy, fleet::FollowerClient& client,
                              const std::vector<navigation::LearnedView>& learned, double wait_s);

}  // namespace mapless::run
