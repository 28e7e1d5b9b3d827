// Horizontal image displacement between a reference and a current image of the same place:
// dx = x_in_current - x_in_reference for the same scene point (the project's convention). Every
// qualitative teach-and-repeat controller rests on this quantity. Robust to season and lighting:
// upright AKAZE features, a ratio test, a bound on the vertical offset, and a histogram vote over
// the horizontal offsets of all matches, refined by the median of the winning bin's neighbourhood.
#pragma once

#include <opencv2/core.hpp>
#include <vector>

#include "mapless/features/features.h"

namespace mapless::features {

struct ShiftOptions {
  FeatureOptions features{DetectorType::kAkazeUpright};
  MatchOptions matching;  // ratio 0.85 by default
  double bin_px = 10.0;   // histogram bin width
  int min_votes = 5;      // fewer supporting matches: not ok
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

ShiftEstimate EstimateShift(const Features& reference, const Features& current,
                            const ShiftOptions& options);
ShiftEstimate EstimateShift(const cv::Mat& reference, const cv::Mat& current,
                            const ShiftOptions& options);

}  // namespace mapless::features
