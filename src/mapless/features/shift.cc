#include "mapless/features/shift.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <utility>

#include "mapless/core/check.h"

namespace mapless::features {

void ShiftOptions::Validate() const {
  features.Validate();
  matching.Validate();
  MAPLESS_CHECK(bin_px > 0.0, "ShiftOptions.bin_px = " << bin_px << "; must be > 0");
  MAPLESS_CHECK(bin_dy_px >= 0.0 && std::isfinite(bin_dy_px),
                "ShiftOptions.bin_dy_px = " << bin_dy_px << "; must be >= 0 (0: dx alone)");
  MAPLESS_CHECK(min_votes >= 1, "ShiftOptions.min_votes = " << min_votes << "; must be >= 1");
}

namespace {

// The estimate from the offsets that support the winning bin: their median, ok with min_votes.
ShiftEstimate FromSupport(std::vector<double> support, int matches, int min_votes) {
  ShiftEstimate out;
  out.matches = matches;
  out.inliers = static_cast<int>(support.size());
  if (support.empty()) return out;
  std::nth_element(support.begin(), support.begin() + static_cast<long>(support.size() / 2),
                   support.end());
  out.dx_px = support[support.size() / 2];
  out.ok = out.inliers >= min_votes;
  return out;
}

}  // namespace

ShiftEstimate VoteShift(const std::vector<double>& dx_px, double bin_px, int min_votes) {
  ShiftEstimate out;
  out.matches = static_cast<int>(dx_px.size());
  if (dx_px.empty()) return out;
  std::map<long, int> histogram;
  for (double d : dx_px) ++histogram[static_cast<long>(std::floor(d / bin_px))];
  // The bin whose neighbourhood (itself and both neighbours) holds the most votes; ties go to the
  // smaller offset, so the result does not depend on map order.
  long best_bin = 0;
  int best_votes = -1;
  for (const auto& [bin, count] : histogram) {
    int votes = count;
    if (auto it = histogram.find(bin - 1); it != histogram.end()) votes += it->second;
    if (auto it = histogram.find(bin + 1); it != histogram.end()) votes += it->second;
    if (votes > best_votes) {
      best_votes = votes;
      best_bin = bin;
    }
  }
  const double centre = (static_cast<double>(best_bin) + 0.5) * bin_px;
  std::vector<double> support;
  for (double d : dx_px) {
    if (std::abs(d - centre) <= 1.5 * bin_px) support.push_back(d);
  }
  return FromSupport(std::move(support), out.matches, min_votes);
}

ShiftEstimate VoteShift2D(const std::vector<double>& dx_px, const std::vector<double>& dy_px,
                          double bin_px, double bin_dy_px, int min_votes) {
  MAPLESS_CHECK(dx_px.size() == dy_px.size(),
                "VoteShift2D: " << dx_px.size() << " dx but " << dy_px.size() << " dy");
  if (bin_dy_px <= 0.0) return VoteShift(dx_px, bin_px, min_votes);
  ShiftEstimate out;
  out.matches = static_cast<int>(dx_px.size());
  if (dx_px.empty()) return out;
  using Bin = std::pair<long, long>;
  std::map<Bin, int> histogram;
  for (std::size_t i = 0; i < dx_px.size(); ++i) {
    ++histogram[{static_cast<long>(std::floor(dx_px[i] / bin_px)),
                 static_cast<long>(std::floor(dy_px[i] / bin_dy_px))}];
  }
  // Ties go to the first bin in map order (smaller dx, then smaller dy): deterministic.
  Bin best{0, 0};
  int best_votes = -1;
  for (const auto& [bin, count] : histogram) {
    int votes = 0;
    for (long i = -1; i <= 1; ++i) {
      for (long j = -1; j <= 1; ++j) {
        if (auto it = histogram.find({bin.first + i, bin.second + j}); it != histogram.end())
          votes += it->second;
      }
    }
    if (votes > best_votes) {
      best_votes = votes;
      best = bin;
    }
  }
  const double cx = (static_cast<double>(best.first) + 0.5) * bin_px;
  const double cy = (static_cast<double>(best.second) + 0.5) * bin_dy_px;
  std::vector<double> support;
  for (std::size_t i = 0; i < dx_px.size(); ++i) {
    if (std::abs(dx_px[i] - cx) <= 1.5 * bin_px && std::abs(dy_px[i] - cy) <= 1.5 * bin_dy_px)
      support.push_back(dx_px[i]);
  }
  return FromSupport(std::move(support), out.matches, min_votes);
}

ShiftEstimate EstimateShift(const Features& reference, const Features& current,
                            const ShiftOptions& options) {
  const std::vector<cv::DMatch> matches = MatchFeatures(reference, current, options.matching);
  std::vector<double> dx;
  std::vector<double> dy;
  dx.reserve(matches.size());
  dy.reserve(matches.size());
  for (const auto& m : matches) {
    const cv::Point2f& a = reference.keypoints[static_cast<std::size_t>(m.queryIdx)].pt;
    const cv::Point2f& b = current.keypoints[static_cast<std::size_t>(m.trainIdx)].pt;
    dx.push_back(b.x - a.x);
    dy.push_back(b.y - a.y);
  }
  return VoteShift2D(dx, dy, options.bin_px, options.bin_dy_px, options.min_votes);
}

ShiftEstimate EstimateShift(const cv::Mat& reference, const cv::Mat& current,
                            const ShiftOptions& options) {
  options.Validate();
  const FeatureExtractor extractor(options.features);
  return EstimateShift(extractor.Extract(reference), extractor.Extract(current), options);
}

}  // namespace mapless::features
