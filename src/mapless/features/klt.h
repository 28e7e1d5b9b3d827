// KLT (pyramidal Lucas-Kanade) tracking of sparse points between consecutive frames, with a
// forward-backward check that rejects points whose track does not return to where it started.
// The funnel-lane paper tracks with KLT and a 31x31 window.
#pragma once

#include <opencv2/core.hpp>
#include <vector>

namespace mapless::features {

struct KltOptions {
  int window_px = 31;                    // square search window (the paper's [31 31])
  int pyramid_levels = 3;                // levels above the base image
  double max_forward_backward_px = 1.0;  // reject if tracking back misses the start by more
  int max_iterations = 30;
  double epsilon = 0.01;
  void Validate() const;
};

struct KltResult {
  std::vector<cv::Point2f> points;  // tracked position in the current frame, one per input point
  std::vector<bool> ok;             // whether each point was tracked
  int tracked = 0;                  // number of ok points
};

KltResult TrackKlt(const cv::Mat& previous, const cv::Mat& current,
                   const std::vector<cv::Point2f>& points, const KltOptions& options);

}  // namespace mapless::features
