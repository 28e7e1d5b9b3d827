// RepeatSession with experiences (issue 45; experiences.h): a keyframe's learned views, the view a
// destination is steered by, and learning the frame at a switch. The rest of the session is in
// repeat.cc.
#include <algorithm>
#include <string>
#include <utility>

#include "mapless/navigation/repeat.h"

namespace mapless::navigation {

void RepeatSession::AddKeyframeFeatures(const route::Keyframe& kf) {
  features::Features f;
  f.keypoints = kf.keypoints;
  f.descriptors = kf.descriptors;
  f.binary = features::IsBinary(options_.features.type);
  keyframe_features_.push_back(std::move(f));
  learned_views_.emplace_back();
  chosen_view_.push_back(-1);
  AddNewViews(learned_views_.size() - 1, kf);
}

void RepeatSession::AddNewViews(std::size_t at, const route::Keyframe& kf) {
  std::vector<View>& views = learned_views_[at];
  for (std::size_t i = views.size(); i < kf.views.size(); ++i) {
    const route::KeyframeView& v = kf.views[i];
    View view;
    view.features.keypoints = v.keypoints;
    view.features.descriptors = v.descriptors;
    view.features.binary = features::IsBinary(options_.features.type);
    view.offset_px = v.offset_px;
    views.push_back(std::move(view));
  }
}

void RepeatSession::MatchKeyframe(int k, std::vector<cv::Point2f>* current_px,
                                  std::vector<cv::Point2f>* keyframe_px,
                                  std::vector<cv::Point2f>* descriptor_matched) {
  const auto index = static_cast<std::size_t>(k);
  const int views = 1 + static_cast<int>(learned_views_[index].size());
  int& chosen = chosen_view_[index];
  if (views == 1 ||
      (chosen >= 0 && k == destination_ && last_matches_ >= options_.recovery_min_features)) {
    MatchView(k, std::max(0, chosen), current_px, keyframe_px, descriptor_matched);
    return;
  }
  // Every view; the one with the most matches (ties: the older) is steered by.
  int best = -1;
  std::vector<cv::Point2f> cur, kp, scene;
  for (int v = 0; v < views; ++v) {
    MatchView(k, v, &cur, &kp, &scene);
    if (best >= 0 && cur.size() <= current_px->size()) continue;
    best = v;
    *current_px = cur;
    *keyframe_px = kp;
    if (descriptor_matched != nullptr) *descriptor_matched = scene;
  }
  chosen = best;
}

void RepeatSession::MaybeLearn(RepeatStep* step) {
  if (frames_since_detect_ != 0 || current_.keypoints.empty() || current_px_.empty()) return;
  ViewChoice choice;
  choice.view = std::max(0, chosen_view_[static_cast<std::size_t>(destination_)]);
  choice.shift.ok = true;
  choice.shift.inliers = last_matches_;
  const auto why = WhyLearn(choice, options_.experiences);
  if (!why) return;
  LearnedView learned;
  learned.keyframe = destination_;
  learned.features = current_;
  learned.offset_px = MedianDx(destination_px_, current_px_);
  learned.why = "keyframe " + std::to_string(destination_) + ": " + *why;
  step->learned = destination_;
  step->learned_why = learned.why;
  learned_.push_back(std::move(learned));
}

}  // namespace mapless::navigation
