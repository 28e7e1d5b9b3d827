// RepeatSession's per-frame features (issue 44): detected once per frame, and with
// RepeatOptions::threads 2 while the obstacle watch looks at the same frame on a second thread.
// The watch reads the frame and its own state, the detector only the frame, and the detector is
// a pure function of it, so the features, and every decision made with them, are those of one
// thread; only the frame's latency changes. The rest of the session is in repeat.cc.
#include <memory>
#include <utility>
#include <vector>

#include "mapless/navigation/repeat.h"

namespace mapless::navigation {

ObstacleCheck RepeatSession::WatchAndDetect(const cv::Mat& grey, Timestamp t_ns, double dt) {
  // The taught scene: the features whose descriptors matched the route on the previous frame.
  // Going round an obstacle, the last frame's match with the route is stale: no known scene.
  const auto look = [&] {
    return watch_.Update(grey, t_ns, last_command_.v_mps * dt, last_command_.omega_radps * dt,
                         detour_ ? std::vector<cv::Point2f>{} : scene_px_, RouteLeftM());
  };
  // Will the method detect on this frame? (TrackDestination's refresh; a switch detects on the
  // same frame too, and uses these.) When it does not, nothing runs beside the watch.
  const bool detect = carry_active_ || reacquire_ || previous_.empty() ||
                      static_cast<int>(current_px_.size()) < options_.min_features ||
                      (options_.redetect_every_frames > 0 &&
                       frames_since_detect_ + 1 >= options_.redetect_every_frames);
  if (options_.threads < 2 || !options_.obstacle.enabled || detour_ || !detect) return look();
  if (!watcher_) watcher_ = std::make_unique<Worker>();
  ObstacleCheck check;
  watcher_->Start([&] { check = look(); });
  try {
    frame_features_ = extractor_.Extract(grey);
  } catch (...) {
    watcher_->Wait();  // the watch reads this frame: it ends before the frame goes
    throw;
  }
  watcher_->Wait();
  return check;
}

const features::Features& RepeatSession::FrameFeatures(const cv::Mat& grey) {
  if (!frame_features_) frame_features_ = extractor_.Extract(grey);
  return *frame_features_;
}

}  // namespace mapless::navigation
