// Horizontal image displacement between a reference and a current image of the same place:
// dx = x_in_current - x_in_reference for the same scene point (the project's convention). Every
// qualitative teach-and-repeat controller rests on this quantity. Robust to season and lighting:
// upright AKAZE keypoints described by upright SIFT, cross-checked matches (each the other's best),
// and a vote over the (dx, dy) offsets of all matches: the camera's height and pitch change between
// sessions, so the scene moves by one common offset in both directions, and a false match rarely
// agrees with it in both. The winner is refined by the median dx of its neighbourhood.
// Chosen on the 660 ordered session pairs of `stromovka_sessions` (docs/results.md, real images).
#pragma once

#include <opencv2/core.hpp>
#include <vector>

#include "mapless/features/features.h"

namespace mapless::features {

struct ShiftOptions {
  FeatureOptions features{DetectorType::kAkazeSift, 1500};
  MatchOptions matching{1.0, 1e9, true};  // cross-checked, no ratio test
  double bin_px = 10.0;                   // histogram bin width, horizontal
  double bin_dy_px = 10.0;                // ... vertical (0: vote on dx alone)
  int min_votes = 5;                      // fewer supporting matches: not ok
  void Validate() const;
};

struct ShiftEstimate {
  bool ok = false;
  double dx_px = 0.0;  // x_in_current - x_in_reference
  int matches = 0;     // matches after the ratio test
  int inliers = 0;     // matches that support dx
};

// Votes over horizontal offsets (one per match); pure, for tests and other estimators.
ShiftEstimate VoteShift(const std::vector<double>& dx_px, double bin_px, int min_votes);
// Votes over (dx, dy) offsets (one pair per match): the bin whose 3x3 neighbourhood holds the most
// votes; dx is the median dx of the matches within 1.5 bins of its centre in both directions.
// bin_dy_px <= 0 votes on dx alone (VoteShift).
ShiftEstimate VoteShift2D(const std::vector<double>& dx_px, const std::vector<double>& dy_px,
                          double bin_px, double bin_dy_px, int min_votes);

ShiftEstimate EstimateShift(const Features& reference, const Features& current,
                            const ShiftOptions& options);
ShiftEstimate EstimateShift(const cv::Mat& reference, const cv::Mat& current,
                            const ShiftOptions& options);

}  // namespace mapless::features
