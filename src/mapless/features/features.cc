#include "mapless/features/features.h"

#include <cmath>
#include <opencv2/imgproc.hpp>

#include "mapless/core/check.h"

namespace mapless::features {
namespace {

struct TypeName {
  DetectorType type;
  const char* name;
};
constexpr TypeName kTypeNames[] = {{DetectorType::kOrb, "orb"},
                                   {DetectorType::kAkaze, "akaze"},
                                   {DetectorType::kAkazeUpright, "akaze_upright"},
                                   {DetectorType::kSift, "sift"}};

}  // namespace

DescriptorLayout DescriptorLayoutOf(DetectorType type) {
  switch (type) {
    case DetectorType::kOrb:
      return {CV_8U, 32};
    case DetectorType::kAkaze:
    case DetectorType::kAkazeUpright:
      return {CV_8U, 61};  // MLDB, full size: 486 bits
    case DetectorType::kSift:
      return {CV_32F, 128};
  }
  return {};
}

DetectorType ParseDetectorType(const std::string& name) {
  for (const auto& t : kTypeNames) {
    if (name == t.name) return t.type;
  }
  throw InputError("unknown detector '" + name + "' (known: orb, akaze, akaze_upright, sift)");
}

const char* DetectorTypeName(DetectorType type) {
  for (const auto& t : kTypeNames) {
    if (type == t.type) return t.name;
  }
  return "?";
}

void FeatureOptions::Validate() const {
  MAPLESS_CHECK(max_features >= 10 && max_features <= 100000,
                "FeatureOptions.max_features = " << max_features << "; must be in [10, 100000]");
  MAPLESS_CHECK(
      orb_fast_threshold >= 1 && orb_fast_threshold <= 255,
      "FeatureOptions.orb_fast_threshold = " << orb_fast_threshold << "; must be in [1, 255]");
  MAPLESS_CHECK(akaze_threshold > 0.0,
                "FeatureOptions.akaze_threshold = " << akaze_threshold << "; must be > 0");
}

void MatchOptions::Validate() const {
  MAPLESS_CHECK(ratio > 0.0 && ratio <= 1.0,
                "MatchOptions.ratio = " << ratio << "; must be in (0, 1]");
  MAPLESS_CHECK(max_dy_px > 0.0, "MatchOptions.max_dy_px = " << max_dy_px << "; must be > 0");
  MAPLESS_CHECK(max_ddx_px > 0.0, "MatchOptions.max_ddx_px = " << max_ddx_px << "; must be > 0");
  MAPLESS_CHECK(std::isfinite(expected_dx_px),
                "MatchOptions.expected_dx_px = " << expected_dx_px << "; must be finite");
}

FeatureExtractor::FeatureExtractor(FeatureOptions options) : options_(options) {
  options_.Validate();
  switch (options_.type) {
    case DetectorType::kOrb:
      detector_ = cv::ORB::create(options_.max_features, 1.2f, 8, 31, 0, 2, cv::ORB::HARRIS_SCORE,
                                  31, options_.orb_fast_threshold);
      break;
    case DetectorType::kAkaze:
      detector_ = cv::AKAZE::create(cv::AKAZE::DESCRIPTOR_MLDB, 0, 3,
                                    static_cast<float>(options_.akaze_threshold));
      break;
    case DetectorType::kAkazeUpright:
      detector_ = cv::AKAZE::create(cv::AKAZE::DESCRIPTOR_MLDB_UPRIGHT, 0, 3,
                                    static_cast<float>(options_.akaze_threshold));
      break;
    case DetectorType::kSift:
      detector_ = cv::SIFT::create(options_.max_features);
      break;
  }
}

Features FeatureExtractor::Extract(const cv::Mat& image) const {
  MAPLESS_CHECK(!image.empty(), "FeatureExtractor: empty image");
  cv::Mat grey = image;
  if (image.channels() == 3) cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  Features out;
  out.binary = options_.type != DetectorType::kSift;
  detector_->detectAndCompute(grey, cv::noArray(), out.keypoints, out.descriptors);
  return out;
}

std::vector<cv::DMatch> MatchFeatures(const Features& query, const Features& train,
                                      const MatchOptions& options) {
  std::vector<cv::DMatch> out;
  if (query.descriptors.empty() || train.descriptors.empty()) return out;
  MAPLESS_CHECK(query.binary == train.binary && query.descriptors.cols == train.descriptors.cols,
                "MatchFeatures: descriptors of different kinds");
  cv::BFMatcher matcher(query.binary ? cv::NORM_HAMMING : cv::NORM_L2);
  const bool guided = options.max_ddx_px < 1e8;
  cv::Mat mask;  // query x train, 1 where a match is allowed (guided matching only)
  if (guided) {
    mask = cv::Mat::zeros(static_cast<int>(query.keypoints.size()),
                          static_cast<int>(train.keypoints.size()), CV_8U);
    for (int i = 0; i < mask.rows; ++i) {
      const cv::Point2f& a = query.keypoints[static_cast<std::size_t>(i)].pt;
      auto* row = mask.ptr<uchar>(i);
      for (int j = 0; j < mask.cols; ++j) {
        const cv::Point2f& b = train.keypoints[static_cast<std::size_t>(j)].pt;
        row[j] = std::abs(a.x - b.x - options.expected_dx_px) <= options.max_ddx_px &&
                 std::abs(a.y - b.y) <= options.max_dy_px;
      }
    }
  }
  std::vector<std::vector<cv::DMatch>> knn;
  matcher.knnMatch(query.descriptors, train.descriptors, knn, 2, mask);
  std::vector<int> best_query_for_train;
  if (options.mutual) {
    std::vector<cv::DMatch> back;
    matcher.match(train.descriptors, query.descriptors, back,
                  guided ? cv::Mat(mask.t()) : cv::Mat());
    best_query_for_train.assign(train.keypoints.size(), -1);
    for (const auto& m : back)
      best_query_for_train[static_cast<std::size_t>(m.queryIdx)] = m.trainIdx;
  }
  for (const auto& k : knn) {
    if (k.empty()) continue;
    if (k.size() >= 2 && !(k[0].distance < options.ratio * k[1].distance)) continue;
    const cv::Point2f& a = query.keypoints[static_cast<std::size_t>(k[0].queryIdx)].pt;
    const cv::Point2f& b = train.keypoints[static_cast<std::size_t>(k[0].trainIdx)].pt;
    if (std::abs(b.y - a.y) > options.max_dy_px) continue;
    if (options.mutual &&
        best_query_for_train[static_cast<std::size_t>(k[0].trainIdx)] != k[0].queryIdx) {
      continue;
    }
    out.push_back(k[0]);
  }
  return out;
}

}  // namespace mapless::features
