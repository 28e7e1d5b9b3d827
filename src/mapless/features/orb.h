// ORB keypoints and descriptors exactly as OpenCV's cv::ORB computes them, at less cost.
//
// OpenCV's ORB (4.x; Harris score, 31-pixel patch and edge, two-point tests, first level 0, no
// mask) runs FAST over the whole of every pyramid level and then drops each corner within 31 px
// of the level's edge: at 320x240 that is half of level 0's area and most of the small levels',
// and with mapless's FAST threshold of 10 FAST is two thirds of ORB's time. OrbDetector runs FAST
// only where a corner can be kept (and 4 px beyond, so the non-maximum suppression of the kept
// corners sees the same neighbours), builds the pyramid without OpenCV's reflected borders (no
// keypoint, Harris window, orientation patch or descriptor test reaches them) and blurs only the
// part of each level the descriptors read. Every other step is OpenCV's own computation, the
// public functions (FAST, resize, GaussianBlur, KeyPointsFilter) called as cv::ORB calls them, so
// the keypoints and descriptors are identical, in the same order (tested bit for bit).
//
// The 256 point pairs of ORB's descriptor are not copied from OpenCV: they are read off
// cv::ORB::compute at first use, with images of a step edge at every position (OrbTestPairs).
#pragma once

#include <opencv2/core.hpp>
#include <vector>

namespace mapless::features {

// One binary test of the ORB descriptor: bit = blurred(first) < blurred(second), offsets from
// the keypoint in pixels at its pyramid level, before rotation by the keypoint's angle.
struct OrbTestPair {
  cv::Point first;
  cv::Point second;
};

// The 256 tests, in descriptor bit order (byte i bit j = test 8i+j), as cv::ORB uses them; empty
// when they could not be read off this OpenCV (then OrbDetector falls back to cv::ORB).
const std::vector<OrbTestPair>& OrbTestPairs();

// cv::fastAtan2(y, x) (degrees in [0, 360): OpenCV 4's scalar 7th-order polynomial), computed
// here for the keypoints' angles. OpenCV's arm64 build contracts the polynomial into fused
// multiply-adds, and its angles differ from x86-64's in the last place; a descriptor's rotated
// test points then cross a pixel now and then, and so do the matches and the robot's decisions.
// This one rounds alike on both (mapless builds with -ffp-contract=off) and is bit for bit
// cv::fastAtan2 on x86-64 (tested).
float FastAtan2Degrees(float y, float x);

class OrbDetector {
 public:
  // As cv::ORB::create(max_features, scale_factor, levels, 31, 0, 2, HARRIS_SCORE, 31,
  // fast_threshold).
  OrbDetector(int max_features, int fast_threshold, float scale_factor = 1.2f, int levels = 8);

  // Keypoints and descriptors (one 32-byte row each) of an image, as
  // cv::ORB::detectAndCompute(image, noArray(), keypoints, descriptors); an image that is not
  // 8-bit grey goes to cv::ORB itself.
  void DetectAndCompute(const cv::Mat& grey, std::vector<cv::KeyPoint>* keypoints,
                        cv::Mat* descriptors) const;

 private:
  int max_features_;
  int fast_threshold_;
  double scale_factor_;
  int levels_;
};

}  // namespace mapless::features
