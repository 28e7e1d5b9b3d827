// Feature detection, description and matching: the front end of the funnel-lane methods.
// Detectors: ORB (default), AKAZE, upright AKAZE (no rotation invariance: a ground robot's camera
// does not roll, and dropping invariance makes descriptors more distinctive across seasons) and
// SIFT. Debian's OpenCV has no SURF, which the funnel-lane paper used.
#pragma once

#include <memory>
#include <opencv2/core.hpp>
#include <opencv2/features2d.hpp>
#include <string>
#include <vector>

#include "mapless/features/orb.h"

namespace mapless::features {

// kAkazeSift: upright AKAZE keypoints described by upright SIFT (the shift estimator's default:
// AKAZE's nonlinear scale space finds corners that survive the seasons, SIFT's gradient histograms
// describe them more distinctively than MLDB's binary tests; docs/results.md, real images).
enum class DetectorType { kOrb, kAkaze, kAkazeUpright, kSift, kAkazeSift };

// "orb", "akaze", "akaze_upright", "sift", "akaze_sift"; throws InputError on an unknown name.
DetectorType ParseDetectorType(const std::string& name);
const char* DetectorTypeName(DetectorType type);

// The descriptors a detector writes: OpenCV element type and length per keypoint (ORB 32 bytes,
// AKAZE and upright AKAZE 61 bytes, SIFT 128 floats). Routes are checked against it on loading.
struct DescriptorLayout {
  int type = 0;  // CV_8U or CV_32F
  int length = 0;
};
DescriptorLayout DescriptorLayoutOf(DetectorType type);
// Hamming (binary descriptors) or L2 distance.
bool IsBinary(DetectorType type);

struct FeatureOptions {
  DetectorType type = DetectorType::kOrb;
  int max_features = 500;           // ORB, SIFT, AKAZE+SIFT: keep at most this many (strongest)
  int orb_fast_threshold = 10;      // ORB: FAST corner threshold, grey levels (OpenCV's default
                                    // is 20; 10 keeps features on low-texture walls)
  double akaze_threshold = 0.0005;  // AKAZE: detector response threshold
  void Validate() const;            // throws InputError naming the field
};

struct Features {
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat descriptors;  // one row per keypoint
  bool binary = true;   // Hamming (ORB, AKAZE) or L2 (SIFT) distance
};

// Holds the detector (not thread-safe: one per thread). ORB is OrbDetector: OpenCV's ORB, the
// same keypoints and descriptors at less cost (orb.h).
class FeatureExtractor {
 public:
  explicit FeatureExtractor(FeatureOptions options);
  // Detects and describes features of a grey (or colour, converted) image.
  Features Extract(const cv::Mat& image) const;
  const FeatureOptions& options() const { return options_; }

 private:
  FeatureOptions options_;
  std::unique_ptr<OrbDetector> orb_;  // ORB
  cv::Ptr<cv::Feature2D> detector_;   // the others (the keypoints of kAkazeSift)
  cv::Ptr<cv::Feature2D> describer_;  // kAkazeSift: SIFT on the upright AKAZE keypoints
};

struct MatchOptions {
  double ratio = 0.85;     // Lowe's ratio test: best distance < ratio * second best (1: none)
  double max_dy_px = 1e9;  // reject matches whose vertical offset exceeds this
  bool mutual = false;     // keep only matches that are also best in the other direction
  // Guided matching: when max_ddx_px is finite, a query feature at x may only match a train
  // feature at x - expected_dx_px +- max_ddx_px (and within max_dy_px vertically), and the ratio
  // test compares only candidates inside that window. A displacement predicted from the previous
  // frame keeps a repeating texture (bricks, fences) from matching one period away.
  double expected_dx_px = 0.0;  // predicted x_query - x_train
  double max_ddx_px = 1e9;
  void Validate() const;
};

// Matches of query features to train features (queryIdx into `query`, trainIdx into `train`).
std::vector<cv::DMatch> MatchFeatures(const Features& query, const Features& train,
                                      const MatchOptions& options);

// The same matches with OpenCV's BFMatcher (the guided window as its mask), for any descriptor.
// MatchFeatures uses it for float descriptors; binary ones have a faster matcher that gives
// exactly these matches (tested against this function).
std::vector<cv::DMatch> MatchFeaturesBruteForce(const Features& query, const Features& train,
                                                const MatchOptions& options);

}  // namespace mapless::features
