// Experiences (issue 45; not in the seed papers): a place of a route holds the view it was taught
// with and up to max_views - 1 views learned on later visits, each with the horizontal offset the
// route measured when it learned it. A visit is localized against the view that matches it best
// and its offset chained back to the taught view, so a place whose appearance drifts (seasons,
// light, parked cars) is still recognized by the view nearest to today's. The same idea as VT&R3's
// multi-experience localization and the Bearnav group's map updates, on the funnel lane's quantity:
// the horizontal image displacement (features/shift.h).
//
// Pure: views in, choices and decisions out. Where the views live (the route store) and when a
// visit happens (a repeat reaching a keyframe, a session of a multi-session dataset) is the
// caller's.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "mapless/features/features.h"
#include "mapless/features/shift.h"
#include "mapless/route/route.h"

namespace mapless::navigation {

struct ExperienceOptions {
  // Views per place, the taught one included; the least recently useful learned view makes room.
  int max_views = 5;
  // A visit is learned as a new view when the best view supports the shift with at least
  // sure_inliers matches (the place is certain) and fewer than changed_inliers (its appearance
  // has moved away from every view the place has).
  int sure_inliers = 12;
  int changed_inliers = 40;
  void Validate() const;
};

struct ExperienceView {
  features::Features features;
  double offset_px = 0.0;  // x in this view - x in the taught view (0 for the taught view)
  int learned_at = 0;      // the visit that learned it (0: the teach)
  int last_used = 0;       // the last visit at which it was the best view
};

struct ViewChoice {
  int view = -1;                  // the best view; -1 when none gives a shift
  features::ShiftEstimate shift;  // the current frame against that view
  double taught_dx_px = 0.0;      // the shift chained to the taught view: shift.dx_px + its offset
};

// The view whose shift has the most inliers (ties: the older view); -1 when no view gives an ok
// shift.
ViewChoice ChooseView(const std::vector<ExperienceView>& views, const features::Features& current,
                      const features::ShiftOptions& options);

// Why this visit should be learned ("best view 2 supports the shift with 23 matches, fewer than
// 40: the place looks different today"), or nullopt when it should not.
std::optional<std::string> WhyLearn(const ViewChoice& choice, const ExperienceOptions& options);

// The chosen view was useful at visit `visit` (what pruning keeps).
void MarkUsed(std::vector<ExperienceView>* views, const ViewChoice& choice, int visit);

// Adds the current frame as a view learned at visit `visit`, with the offset the choice measured;
// when the place is full, the learned view used least recently (then the oldest) makes room. The
// taught view (index 0) always stays.
void LearnView(std::vector<ExperienceView>* views, const ViewChoice& choice,
               features::Features current, int visit, const ExperienceOptions& options);

// A view a repeat learned (RepeatOptions::learn): the keyframe, the frame's features, the offset
// the repeat measured (x in the frame - x in the taught view: the median over its matches).
struct LearnedView {
  int keyframe = 0;
  features::Features features;
  double offset_px = 0.0;
  std::string why;
};

// One repeat's visit of a route: route->visits + 1; the view each keyframe was steered by
// (`used_views`, RepeatSession::used_views(): 0 the taught one, i + 1 learned view i, -1 none)
// marked used at it; the learned views added, the least recently useful learned view making room
// when a keyframe has options.max_views. Returns the number of views added.
int ApplyVisit(route::Route* route, const std::vector<int>& used_views,
               std::vector<LearnedView> learned, const ExperienceOptions& options);

// Keeps at most `max_views` views per keyframe (the taught one included, so max_views - 1
// learned): the learned views used least recently (then the oldest) go first, as when a place
// makes room. `mapless route prune`. Returns the number of views removed; throws InputError when
// max_views < 1.
int PruneViews(route::Route* route, int max_views);

// Adds to `into` the learned views of `from`, a route taught together with it (a copy that another
// robot or another run repeated with --learn: the same keyframes, feature for feature; otherwise
// InputError naming the first keyframe that differs). A view `into` has already (the same
// features and offset) is skipped. The merged views keep their order of visits, after every
// visit of `into` (their visit numbers are shifted by into->visits, which grows by
// from.visits), and each keyframe keeps at most max_views views, the least recently useful
// making room. `mapless route merge`. Returns the number of views merged (some may have made
// room again at once, when they were used less recently than the views there).
int MergeViews(route::Route* into, const route::Route& from, int max_views);

}  // namespace mapless::navigation
