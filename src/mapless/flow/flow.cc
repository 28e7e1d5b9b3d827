#include "mapless/flow/flow.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>
#include <utility>

#include "mapless/core/check.h"

namespace mapless::flow {
namespace {

// OpenCV's thread count for a scope, the process's restored at its end (also when the call throws).
class OpenCvThreads {
 public:
  explicit OpenCvThreads(int threads) : before_(cv::getNumThreads()) {
    if (threads != before_) cv::setNumThreads(threads);
    changed_ = threads != before_;
  }
  ~OpenCvThreads() {
    if (changed_) cv::setNumThreads(before_);
  }
  OpenCvThreads(const OpenCvThreads&) = delete;
  OpenCvThreads& operator=(const OpenCvThreads&) = delete;

 private:
  int before_;
  bool changed_ = false;
};

cv::Mat ToGrey(const cv::Mat& image) {
  MAPLESS_CHECK(!image.empty(), "ComputeFlow: empty image");
  cv::Mat grey = image;
  if (image.channels() == 3) cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  if (image.channels() == 4) cv::cvtColor(image, grey, cv::COLOR_BGRA2GRAY);
  MAPLESS_CHECK(grey.type() == CV_8UC1, "ComputeFlow: expected an 8-bit image");
  return grey;
}

}  // namespace

std::pair<cv::Mat, cv::Mat> GreyPair(const cv::Mat& first, const cv::Mat& second, const char* who) {
  cv::Mat a = ToGrey(first);
  cv::Mat b = ToGrey(second);
  MAPLESS_CHECK(a.size() == b.size(), who << ": images of different sizes " << a.cols << "x"
                                          << a.rows << " and " << b.cols << "x" << b.rows);
  return {a, b};
}

FlowMethod ParseFlowMethod(const std::string& name) {
  if (name == "dis") return FlowMethod::kDisFast;
  if (name == "dis_medium") return FlowMethod::kDisMedium;
  if (name == "farneback") return FlowMethod::kFarneback;
  if (name == "lk") return FlowMethod::kDenseLk;
  throw InputError("unknown flow method '" + name + "' (known: dis, dis_medium, farneback, lk)");
}

const char* FlowMethodName(FlowMethod method) {
  switch (method) {
    case FlowMethod::kDisFast:
      return "dis";
    case FlowMethod::kDisMedium:
      return "dis_medium";
    case FlowMethod::kFarneback:
      return "farneback";
    case FlowMethod::kDenseLk:
      return "lk";
  }
  return "?";
}

void DenseLkOptions::Validate() const {
  MAPLESS_CHECK(window >= 3 && window % 2 == 1,
                "DenseLkOptions.window = " << window << "; must be odd and >= 3");
  MAPLESS_CHECK(levels >= 1 && levels <= 8,
                "DenseLkOptions.levels = " << levels << "; must be in [1, 8]");
  MAPLESS_CHECK(iterations >= 1 && iterations <= 20,
                "DenseLkOptions.iterations = " << iterations << "; must be in [1, 20]");
  MAPLESS_CHECK(min_eigen >= 0.0, "DenseLkOptions.min_eigen = " << min_eigen << "; must be >= 0");
}

void FlowOptions::Validate() const {
  MAPLESS_CHECK(dis_max_flow_width_px >= 0, "FlowOptions.dis_max_flow_width_px = "
                                                << dis_max_flow_width_px << "; must be >= 0");
  MAPLESS_CHECK(threads >= 1 && threads <= 8,
                "FlowOptions.threads = " << threads << "; must be in [1, 8]");
  lk.Validate();
}

FlowEstimator::FlowEstimator(FlowOptions options) : options_(std::move(options)) {
  options_.Validate();
}

FlowEstimator& FlowEstimator::operator=(const FlowEstimator& other) {
  if (this != &other) {
    options_ = other.options_;
    dis_.reset();
  }
  return *this;
}

cv::Mat FlowEstimator::Compute(const cv::Mat& first, const cv::Mat& second) {
  const auto [a, b] = GreyPair(first, second, "ComputeFlow");
  // Empty, so that DIS starts afresh: given a flow of the images' size it would take it as its
  // initial estimate.
  cv::Mat flow;
  switch (options_.method) {
    case FlowMethod::kDisFast:
    case FlowMethod::kDisMedium: {
      if (dis_.empty()) {
        dis_ = cv::DISOpticalFlow::create(options_.method == FlowMethod::kDisFast
                                              ? cv::DISOpticalFlow::PRESET_FAST
                                              : cv::DISOpticalFlow::PRESET_MEDIUM);
      }
      if (options_.dis_max_flow_width_px > 0) {
        int scale = 0;
        while ((a.cols >> scale) > options_.dis_max_flow_width_px) ++scale;
        dis_->setFinestScale(scale);
      }
      const OpenCvThreads threads(options_.threads);
      dis_->calc(a, b, flow);
      break;
    }
    case FlowMethod::kFarneback:
      cv::calcOpticalFlowFarneback(a, b, flow, 0.5, 4, 15, 3, 5, 1.1, 0);
      break;
    case FlowMethod::kDenseLk:
      flow = DenseLucasKanade(a, b, options_.lk);
      break;
  }
  return flow;
}

cv::Mat ComputeFlow(const cv::Mat& first, const cv::Mat& second, const FlowOptions& options) {
  return FlowEstimator(options).Compute(first, second);
}

FlowError EndPointError(const cv::Mat& flow, const cv::Mat& truth, const cv::Mat& valid) {
  MAPLESS_CHECK(flow.type() == CV_32FC2 && truth.type() == CV_32FC2 && flow.size() == truth.size(),
                "EndPointError: flow and truth must be CV_32FC2 of the same size");
  MAPLESS_CHECK(valid.empty() || (valid.type() == CV_8UC1 && valid.size() == flow.size()),
                "EndPointError: the valid mask must be CV_8UC1 of the flow's size");
  std::vector<double> errors;
  errors.reserve(flow.total());
  for (int y = 0; y < flow.rows; ++y) {
    const auto* f = flow.ptr<cv::Vec2f>(y);
    const auto* t = truth.ptr<cv::Vec2f>(y);
    const uchar* v = valid.empty() ? nullptr : valid.ptr<uchar>(y);
    for (int x = 0; x < flow.cols; ++x) {
      if (v != nullptr && v[x] == 0) continue;
      if (!(std::abs(t[x][0]) < 1e9f && std::abs(t[x][1]) < 1e9f)) continue;
      errors.push_back(std::hypot(f[x][0] - t[x][0], f[x][1] - t[x][1]));
    }
  }
  FlowError e;
  e.count = static_cast<long>(errors.size());
  if (errors.empty()) return e;
  double sum = 0.0;
  for (double d : errors) sum += d;
  e.mean_epe_px = sum / static_cast<double>(errors.size());
  const auto mid = errors.begin() + static_cast<std::ptrdiff_t>(errors.size() / 2);
  std::nth_element(errors.begin(), mid, errors.end());
  e.median_epe_px = *mid;
  return e;
}

}  // namespace mapless::flow
