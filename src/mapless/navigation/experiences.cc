#include "mapless/navigation/experiences.h"

#include <algorithm>
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

void LearnView(std::vector<ExperienceView>* views, const ViewChoice& choice,
               features::Features current, int visit, const ExperienceOptions& options) {
  MAPLESS_CHECK(choice.view >= 0, "LearnView: the visit was not localized against any view");
  MarkUsed(views, choice, visit);
  if (static_cast<int>(views->size()) >= options.max_views) {
    if (views->size() <= 1) return;  // max_views 1: the taught view only
    // The learned view used least recently, then the oldest: it makes room.
    const auto victim = std::min_element(views->begin() + 1, views->end(),
                                         [](const ExperienceView& a, const ExperienceView& b) {
                                           return std::make_pair(a.last_used, a.learned_at) <
                                                  std::make_pair(b.last_used, b.learned_at);
                                         });
    views->erase(victim);
  }
  ExperienceView view;
  view.features = std::move(current);
  view.offset_px = choice.taught_dx_px;
  view.learned_at = visit;
  view.last_used = visit;
  views->push_back(std::move(view));
}

}  // namespace mapless::navigation
