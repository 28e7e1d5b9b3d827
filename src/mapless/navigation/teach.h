// The teach phase of visual teach & repeat (Kassir et al., Section III): detect features in the
// first frame and track them with KLT through the video; when fewer than half of them (by default)
// are still tracked, the frame becomes a keyframe, features are detected afresh, and tracking goes
// on. The features that survived a whole segment are stored with their coordinates at both ends.
// Pure: frames in, keyframes out; storing them is the caller's business (route::RouteWriter).
#pragma once

#include <memory>
#include <opencv2/core.hpp>
#include <optional>
#include <vector>

#include "mapless/core/worker.h"
#include "mapless/features/features.h"
#include "mapless/features/klt.h"
#include "mapless/route/route.h"

namespace mapless::navigation {

struct TeachOptions {
  features::FeatureOptions features;  // ORB, 500 features by default
  features::KltOptions klt;           // 31x31 window, as in the paper
  // New keyframe when fewer than this fraction of the tracked features survive. The paper uses
  // 0.5; our KLT (with a forward-backward check) keeps features longer than the paper's tracker,
  // and 0.5 leaves keyframes 3-4 m apart: too sparse through sharp low-texture turns (see
  // docs/teach_and_repeat.md). 0.7 is the default.
  double keyframe_tracked_fraction = 0.7;
  // Also a new keyframe when the tracked features' horizontal spread has grown by more than this
  // factor since the last keyframe (not in the paper): with far-away features (outdoors) almost all
  // survive for metres and keyframes end up ~10 m apart, too far to match across the scale change.
  // 0 disables it.
  double max_spread_growth = 1.3;
  // A frame with fewer features than this never becomes a keyframe (the repeat could not match
  // it); the keyframe is deferred to the next frame that has enough, and the deferral counted.
  int min_keyframe_features = 30;
  // Track at most this many of a keyframe's features through its segment, the strongest (Harris
  // response) first; all are stored for matching. 0 (the default) tracks them all. 300 makes the
  // teach step ~1.5x cheaper, but it changes the keyframes (the strongest features die sooner):
  // on the full-resolution tracker it cost the sloped lane a run of 10 on
  // outdoor_loop_cars_removed (docs/teach_and_repeat.md), so it is off.
  int max_tracked_features = 0;
  // 2: the features are tracked in two halves, one on a second thread (KLT tracks each point on
  // its own, so the tracks and keyframes are those of 1, bit for bit; issue 44).
  int threads = 1;
  int thumbnail_width_px = 160;  // width of the stored downscaled image
  void Validate() const;
};

class TeachSession {
 public:
  explicit TeachSession(TeachOptions options);

  // Feeds one frame; returns the keyframe this frame became, if it did. With the robot's
  // odometry pose at the frame, the keyframe keeps it (route::Keyframe::odometry).
  std::optional<route::Keyframe> Update(const cv::Mat& image, Timestamp t_ns,
                                        const std::optional<Pose2>& odometry = std::nullopt);
  // Ends the teach: the last frame becomes the final keyframe unless it already is one or has too
  // few features. Like every keyframe, the first is the first frame with enough features.
  std::optional<route::Keyframe> Finish();

  int keyframe_count() const { return next_index_; }
  // Frames that should have become keyframes but had too few features (a weak stretch of route).
  int deferred_keyframes() const { return deferred_; }
  // Fraction of the current segment's features still tracked (1 right after a keyframe).
  double tracked_fraction() const;

 private:
  // The keyframe `grey` becomes, or nullopt (counted as deferred) with too few features.
  std::optional<route::Keyframe> MakeKeyframe(const cv::Mat& grey, Timestamp t_ns,
                                              const std::optional<Pose2>& odometry);

  // KLT from the previous frame to this one, on two threads with threads 2.
  features::KltResult Track(const features::KltPyramid& pyramid);

  TeachOptions options_;
  features::FeatureExtractor extractor_;
  std::unique_ptr<Worker> tracker_;  // threads 2: tracks the first half of the features
  int next_index_ = 0;
  cv::Mat previous_;
  features::KltPyramid previous_pyramid_;
  Timestamp previous_t_ns_ = 0;
  std::optional<Pose2> previous_odometry_;
  bool previous_is_keyframe_ = false;
  std::vector<cv::Point2f> start_;    // tracked features at the segment's first keyframe
  std::vector<cv::Point2f> current_;  // ... where they are now
  std::size_t initial_count_ = 0;
  int deferred_ = 0;
};

}  // namespace mapless::navigation
