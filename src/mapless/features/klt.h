// KLT (pyramidal Lucas-Kanade) tracking of sparse points between consecutive frames, with a
// forward-backward check that rejects points whose track does not return to where it started.
// The funnel-lane paper tracks with KLT and a 31x31 window.
//
// Where the time goes: the Lucas-Kanade iterations over the window, per point, level and direction
// (the pyramids are ~3% of it). finest_level 1, the default, tracks on the half-resolution image
// with the window halved: the same 31 pixels of the full image around each point, a quarter of the
// samples, ~3x less time; the positions differ by 0.15 px (median) from full-resolution tracking.
// finest_level 0 is the paper's tracker bit for bit (docs/results.md, Teach speed).
#pragma once

#include <opencv2/core.hpp>
#include <vector>

namespace mapless::features {

struct KltOptions {
  int window_px = 31;      // square window, in pixels of the full image (the paper's [31 31])
  int pyramid_levels = 3;  // levels above the full image; the coarsest is 1/8 of its size
  // The finest level tracked: 0 (the default) = the full image; 1 = the half-resolution image, the
  // window halved (15 px there for 31), positions rescaled to the full image.
  int finest_level = 1;
  double max_forward_backward_px = 1.0;  // reject if tracking back misses the start by more (px
                                         // of the full image)
  int max_iterations = 30;
  double epsilon = 0.01;  // iterations stop when the step is below this (px of the finest level)
  // The window side at the finest level tracked (odd).
  int LevelWindowPx() const;
  void Validate() const;
};

// One frame's pyramid with its derivatives, from the finest level tracked up: built once per
// frame and used by both directions of two steps (as the current frame, then as the previous).
struct KltPyramid {
  std::vector<cv::Mat> levels;  // as cv::buildOpticalFlowPyramid returns them (with derivatives)
  cv::Size image_size;          // of the full image
  int max_level = 0;            // pyramid levels above the finest tracked
  bool empty() const { return levels.empty(); }
};
KltPyramid BuildKltPyramid(const cv::Mat& grey, const KltOptions& options);

struct KltResult {
  std::vector<cv::Point2f> points;  // tracked position in the current frame, one per input point
  std::vector<bool> ok;             // whether each point was tracked
  int tracked = 0;                  // number of ok points
};

KltResult TrackKlt(const KltPyramid& previous, const KltPyramid& current,
                   const std::vector<cv::Point2f>& points, const KltOptions& options);
// The same, building both pyramids.
KltResult TrackKlt(const cv::Mat& previous, const cv::Mat& current,
                   const std::vector<cv::Point2f>& points, const KltOptions& options);

}  // namespace mapless::features
