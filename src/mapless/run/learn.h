// `mapless repeat --learn` (issue 45): what one repeat learned, written into its route.
#pragma once

#include <string>
#include <vector>

#include "mapless/navigation/experiences.h"
#include "mapless/route/route.h"

namespace mapless::run {

// Applies the visit (navigation::ApplyVisit) to a copy of `route` and writes it into `dir`
// (route::SaveViews; the caller holds the directory's lock). Returns one line for the log: "route:
// visit 3, 2 views learned (keyframes 4, 5), 7 views in all".
std::string SaveVisit(const std::string& dir, const route::Route& route,
                      const std::vector<int>& used_views,
                      std::vector<navigation::LearnedView> learned,
                      const navigation::ExperienceOptions& options);

// `mapless route prune ROUTE --max-views N`: locks the route directory, keeps at most N views per
// keyframe (navigation::PruneViews) and writes what changed (route::SaveViews: the manifest, then
// the pruned files removed). Returns one line: "ROUTE: 3 learned views pruned, 12 left".
std::string PruneRouteViews(const std::string& dir, int max_views);

// `mapless route merge ROUTE OTHER --max-views N`: the views OTHER learned, merged into ROUTE
// (navigation::MergeViews; both directories locked, OTHER only read). Returns one line:
// "ROUTE: 4 learned views merged from OTHER, 9 in all".
std::string MergeRouteViews(const std::string& dir, const std::string& other, int max_views);

}  // namespace mapless::run
