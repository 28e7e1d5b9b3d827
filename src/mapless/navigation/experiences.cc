#include "mapless/navigation/experiences.h"

#include <algorithm>
#include <opencv2/core.hpp>
#include <utility>

#include "mapless/core/check.h"

namespace mapless::navigation {

void ExperienceOptions::Validate() const {
  MAPLESS_CHECK(max_views >= 1 && max_views <= 64,
                "ExperienceOptions.max_views = " << max_views << "; must be in [1, 64]");
  MAPLESS_CHECK(sure_inliers >= 1,
                "ExperienceOptions.sure_inliers = " << sure_inliers << "; must be >= 1");
  MAPLESS_CHECK(changed_inliers >= sure_inliers,
                "ExperienceOptions.changed_inliers = "
                    << changed_inliers << "; must be >= sure_inliers = " << sure_inliers);
}

ViewChoice ChooseView(const std::vector<ExperienceView>& views, const features::Features& current,
                      const features::ShiftOptions& options) {
  ViewChoice best;
  for (std::size_t v = 0; v < views.size(); ++v) {
    const features::ShiftEstimate shift =
        features::EstimateShift(views[v].features, current, options);
    if (!shift.ok || (best.view >= 0 && shift.inliers <= best.shift.inliers)) continue;
    best.view = static_cast<int>(v);
    best.shift = shift;
    best.taught_dx_px = shift.dx_px + views[v].offset_px;
  }
  return best;
}

std::optional<std::string> WhyLearn(const ViewChoice& choice, const ExperienceOptions& options) {
  if (choice.view < 0 || choice.shift.inliers < options.sure_inliers ||
      choice.shift.inliers >= options.changed_inliers) {
    return std::nullopt;
  }
  return "the best view (" + std::to_string(choice.view) + ") supports the shift with " +
         std::to_string(choice.shift.inliers) + " matches, fewer than " +
         std::to_string(options.changed_inliers) + ": the place looks different today";
}

void MarkUsed(std::vector<ExperienceView>* views, const ViewChoice& choice, int visit) {
  if (choice.view < 0 || choice.view >= static_cast<int>(views->size())) return;
  auto& used = (*views)[static_cast<std::size_t>(choice.view)].last_used;
  used = std::max(used, visit);
}

namespace {

// While `max_learned` or more learned views stand from `first_learned` on, the one used least
// recently (then the oldest) makes room.
// Removes learned views (from index `first_learned` on), least recently used first (then the
// oldest), until at most `keep` are left.
template <typename View>
void KeepAtMost(std::vector<View>* views, std::size_t first_learned, int keep) {
  while (views->size() > first_learned && static_cast<int>(views->size() - first_learned) > keep) {
    const auto victim = std::min_element(views->begin() + static_cast<long>(first_learned),
                                         views->end(), [](const View& a, const View& b) {
                                           return std::make_pair(a.last_used, a.learned_at) <
                                                  std::make_pair(b.last_used, b.learned_at);
                                         });
    views->erase(victim);
  }
}

template <typename View>
void MakeRoom(std::vector<View>* views, std::size_t first_learned, int max_learned) {
  KeepAtMost(views, first_learned, max_learned - 1);
}

}  // namespace

void LearnView(std::vector<ExperienceView>* views, const ViewChoice& choice,
               features::Features current, int visit, const ExperienceOptions& options) {
  MAPLESS_CHECK(choice.view >= 0, "LearnView: the visit was not localized against any view");
  MarkUsed(views, choice, visit);
  if (options.max_views <= 1) return;  // the taught view only
  MakeRoom(views, 1, options.max_views - 1);
  ExperienceView view;
  view.features = std::move(current);
  view.offset_px = choice.taught_dx_px;
  view.learned_at = visit;
  view.last_used = visit;
  views->push_back(std::move(view));
}

int ApplyVisit(route::Route* route, const std::vector<int>& used_views,
               std::vector<LearnedView> learned, const ExperienceOptions& options) {
  options.Validate();
  MAPLESS_CHECK(route->visits < route::kMaxRouteVisits,
                "the route has " << route->visits << " visits, the most it counts");
  const int visit = ++route->visits;
  auto& kfs = route->keyframes;
  for (std::size_t k = 0; k < kfs.size() && k < used_views.size(); ++k) {
    const int v = used_views[k] - 1;
    if (v >= 0 && v < static_cast<int>(kfs[k].views.size()))
      kfs[k].views[static_cast<std::size_t>(v)].last_used = visit;
  }
  int added = 0;
  for (LearnedView& l : learned) {
    MAPLESS_CHECK(l.keyframe >= 0 && l.keyframe < static_cast<int>(kfs.size()),
                  "ApplyVisit: keyframe " << l.keyframe << " is not on the route");
    if (options.max_views <= 1) continue;
    auto& views = kfs[static_cast<std::size_t>(l.keyframe)].views;
    MakeRoom(&views, 0, options.max_views - 1);
    route::KeyframeView view;
    view.keypoints = std::move(l.features.keypoints);
    view.descriptors = l.features.descriptors;
    view.offset_px = l.offset_px;
    view.learned_at = visit;
    view.last_used = visit;
    views.push_back(std::move(view));
    ++added;
  }
  return added;
}

int PruneViews(route::Route* route, int max_views) {
  MAPLESS_CHECK(max_views >= 1, "max_views = " << max_views << "; must be >= 1 (the taught view)");
  int removed = 0;
  for (route::Keyframe& kf : route->keyframes) {
    const std::size_t before = kf.views.size();
    KeepAtMost(&kf.views, 0, max_views - 1);
    removed += static_cast<int>(before - kf.views.size());
  }
  return removed;
}

namespace {

bool SameMat(const cv::Mat& a, const cv::Mat& b) {
  if (a.size() != b.size() || a.type() != b.type()) return false;
  return a.empty() || cv::norm(a, b, cv::NORM_INF) == 0.0;
}

bool SameView(const route::KeyframeView& a, const route::KeyframeView& b) {
  return a.offset_px == b.offset_px && a.keypoints.size() == b.keypoints.size() &&
         SameMat(a.descriptors, b.descriptors);
}

}  // namespace

int MergeViews(route::Route* into, const route::Route& from, int max_views) {
  MAPLESS_CHECK(max_views >= 1, "max_views = " << max_views << "; must be >= 1 (the taught view)");
  MAPLESS_CHECK(into->keyframes.size() == from.keyframes.size() && into->detector == from.detector,
                "the routes were not taught together: "
                    << into->keyframes.size() << " " << into->detector << " keyframes against "
                    << from.keyframes.size() << " " << from.detector);
  for (std::size_t k = 0; k < from.keyframes.size(); ++k) {
    const route::Keyframe& a = into->keyframes[k];
    const route::Keyframe& b = from.keyframes[k];
    MAPLESS_CHECK(a.keypoints.size() == b.keypoints.size() && SameMat(a.descriptors, b.descriptors),
                  "the routes were not taught together: keyframe " << k << " differs");
  }
  MAPLESS_CHECK(from.visits <= route::kMaxRouteVisits - into->visits,
                "the routes have " << into->visits << " and " << from.visits
                                   << " visits: more than " << route::kMaxRouteVisits
                                   << " together");
  const int shift = into->visits;
  int added = 0;
  for (std::size_t k = 0; k < from.keyframes.size(); ++k) {
    auto& views = into->keyframes[k].views;
    for (const route::KeyframeView& v : from.keyframes[k].views) {
      if (std::any_of(views.begin(), views.end(),
                      [&](const route::KeyframeView& w) { return SameView(v, w); }))
        continue;
      route::KeyframeView copy = v;
      copy.learned_at += shift;
      copy.last_used += shift;
      copy.file.clear();  // written anew into the route it joins
      views.push_back(std::move(copy));
      ++added;
    }
    KeepAtMost(&views, 0, max_views - 1);
  }
  // Merging the same route again adds nothing and counts no visits (idempotent): the visits of
  // `from` join only with views that came with them.
  if (added > 0) into->visits += from.visits;
  return added;
}

}  // namespace mapless::navigation
