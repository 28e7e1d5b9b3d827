// Dense optical flow behind one interface (Ohnishi & Imiya, Section 3.2 and Appendix A): OpenCV DIS
// (default, fast or medium preset), Farneback, and the paper's dense pyramidal Lucas-Kanade.
//
// A flow field is CV_32FC2, one (u, v) per pixel of the first image: the point at (x, y) in the
// first image is at (x + u, y + v) in the second.
#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <utility>
#include <vector>

namespace cv {
class DISOpticalFlow;
}  // namespace cv

namespace mapless::flow {

enum class FlowMethod { kDisFast, kDisMedium, kFarneback, kDenseLk };

// "dis" (DIS fast), "dis_medium", "farneback", "lk"; throws InputError on an unknown name.
FlowMethod ParseFlowMethod(const std::string& name);
const char* FlowMethodName(FlowMethod method);

// The paper's dense Lucas-Kanade (Appendix A): a 5x5 window, pyramid levels 0-4 built with the 3x3
// kernel 1/4 (centre), 1/8 (edges), 1/16 (corners), coarse-to-fine with warping. Every pixel is
// solved at once: the structure tensor and the mismatch vector are box-filtered images, and the
// 2x2 systems are solved element-wise.
struct DenseLkOptions {
  int window = 5;          // side of the square window (odd)
  int levels = 5;          // pyramid levels 0..levels-1
  int iterations = 3;      // warping iterations per level
  double min_eigen = 0.5;  // smaller eigenvalue of the window-averaged tensor (grey^2/px^2)
                           // below this: a flat window, no update
  // A 3x3 median of each level's result before it is expanded to the next level. Not in the paper:
  // a 5x5 window leaves isolated wild vectors that the coarse-to-fine expansion spreads.
  bool median = true;
  void Validate() const;
};

struct FlowOptions {
  FlowMethod method = FlowMethod::kDisFast;
  // DIS only: > 0 estimates the flow on the finest pyramid level at most this wide (then
  // upsampled, as DIS does) instead of the preset's finest level (fast: a quarter of the width,
  // medium: half). Nearly all of DIS's time is spent on that level, so a larger camera then costs
  // about what a smaller one does. 0: the preset's.
  int dis_max_flow_width_px = 0;
  // DIS only: OpenCV's threads for the call (cv::setNumThreads around it, the process's count
  // restored after; so one flow at a time per process with threads > 1). The flow is the same on
  // any number: DIS's patch search runs in 8 fixed stripes, its densification is per pixel and its
  // refinement red-black (FlowEstimator.TwoThreadsGiveTheSameFlow). 1 to 8.
  int threads = 1;
  DenseLkOptions lk;
  void Validate() const;
};

// Flow from `first` to `second` (8-bit grey or colour, same size).
cv::Mat ComputeFlow(const cv::Mat& first, const cv::Mat& second, const FlowOptions& options);

// ComputeFlow for a stream of pairs: DIS's pyramids, buffers and variational-refinement objects
// are made once, not at every call (DIS medium at 320x240: about 1 ms of 8, issue 44). The same
// flow as ComputeFlow, bit for bit (FlowEstimator.GivesComputeFlowsFlowBitForBit). A copy starts
// with state of its own; one thread at a time per estimator.
class FlowEstimator {
 public:
  explicit FlowEstimator(FlowOptions options);
  FlowEstimator(const FlowEstimator& other) : FlowEstimator(other.options_) {}
  FlowEstimator& operator=(const FlowEstimator& other);
  cv::Mat Compute(const cv::Mat& first, const cv::Mat& second);

 private:
  FlowOptions options_;
  cv::Ptr<cv::DISOpticalFlow> dis_;  // DIS methods: kept between calls
};

// The paper's pyramid: level 0 is the image (CV_32F), level l+1 is level l smoothed with the 3x3
// kernel above and subsampled by 2.
std::vector<cv::Mat> BuildPyramid(const cv::Mat& grey, int levels);

// `level_flows`, when given, receives each layer's flow u^l (finest first) in that layer's pixels:
// the layer optical flow fields of Section 3.6, for hierarchical dominant planes.
cv::Mat DenseLucasKanade(const cv::Mat& first, const cv::Mat& second, const DenseLkOptions& options,
                         std::vector<cv::Mat>* level_flows = nullptr);

// Which build of the dense LK's vector loops runs: "avx2" on an x86-64 CPU with AVX2, else
// "baseline" (SSE2 on x86-64, NEON on ARM). Both give the same flow, bit for bit.
// UseBaselineDenseLkKernels(true) forces the baseline (tests, the bench).
const char* DenseLkKernels();
void UseBaselineDenseLkKernels(bool baseline);

// Both images as 8-bit grey (colour converted), checked to be the same size; `who` names the
// caller in the error.
std::pair<cv::Mat, cv::Mat> GreyPair(const cv::Mat& first, const cv::Mat& second, const char* who);

// End-point error against ground truth; pixels where `valid` is zero (or the truth is unknown,
// |value| > 1e9 as in Middlebury files) are skipped.
struct FlowError {
  double mean_epe_px = 0.0;
  double median_epe_px = 0.0;
  long count = 0;
};
FlowError EndPointError(const cv::Mat& flow, const cv::Mat& truth, const cv::Mat& valid = {});

}  // namespace mapless::flow
