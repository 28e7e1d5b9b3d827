#include "mapless/flow/flow.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>
#include <utility>

#include "mapless/core/check.h"

namespace mapless::flow {
namespace {

cv::Mat ToGrey(const cv::Mat& image) {
  MAPLESS_CHECK(!image.empty(), "ComputeFlow: empty image");
  cv::Mat grey = image;
  if (image.channels() == 3) cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  if (image.channels() == 4) cv::cvtColor(image, grey, cv::COLOR_BGRA2GRAY);
  MAPLESS_CHECK(grey.type() == CV_8UC1, "ComputeFlow: expected an 8-bit image");
  return grey;
}

// Both images as 8-bit grey, checked to be the same size.
std::pair<cv::Mat, cv::Mat> GreyPair(const cv::Mat& first, const cv::Mat& second, const char* who) {
  cv::Mat a = ToGrey(first);
  cv::Mat b = ToGrey(second);
  MAPLESS_CHECK(a.size() == b.size(), who << ": images of different sizes " << a.cols << "x"
                                          << a.rows << " and " << b.cols << "x" << b.rows);
  return {a, b};
}

// Solves the per-pixel 2x2 systems [a11 a12; a12 a22] d = -[b1; b2] and adds d to `flow`.
void SolveAndAdd(const cv::Mat& a11, const cv::Mat& a12, const cv::Mat& a22, const cv::Mat& b1,
                 const cv::Mat& b2, double min_eigen, cv::Mat* flow) {
  for (int y = 0; y < flow->rows; ++y) {
    const float* p11 = a11.ptr<float>(y);
    const float* p12 = a12.ptr<float>(y);
    const float* p22 = a22.ptr<float>(y);
    const float* q1 = b1.ptr<float>(y);
    const float* q2 = b2.ptr<float>(y);
    auto* f = flow->ptr<cv::Vec2f>(y);
    for (int x = 0; x < flow->cols; ++x) {
      const float s11 = p11[x], s12 = p12[x], s22 = p22[x];
      const float det = s11 * s22 - s12 * s12;
      // Smaller eigenvalue of the tensor, as OpenCV's LK uses it to reject flat windows.
      const float tr = 0.5f * (s11 + s22);
      const float min_eig = tr - std::sqrt(std::max(0.f, tr * tr - det));
      if (min_eig < static_cast<float>(min_eigen) || det <= 0.f) continue;
      const float inv = 1.f / det;
      // One linearisation step is only valid for about a pixel: clamp it.
      const float du = std::clamp((-s22 * q1[x] + s12 * q2[x]) * inv, -1.f, 1.f);
      const float dv = std::clamp((s12 * q1[x] - s11 * q2[x]) * inv, -1.f, 1.f);
      f[x][0] += du;
      f[x][1] += dv;
    }
  }
}

}  // namespace

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
  lk.Validate();
}

std::vector<cv::Mat> BuildPyramid(const cv::Mat& grey, int levels) {
  std::vector<cv::Mat> pyramid;
  cv::Mat level;
  grey.convertTo(level, CV_32F);
  pyramid.push_back(level);
  const cv::Mat kernel = (cv::Mat_<float>(1, 3) << 0.25f, 0.5f, 0.25f);
  for (int l = 1; l < levels; ++l) {
    const cv::Mat& prev = pyramid.back();
    if (prev.cols < 8 || prev.rows < 8) break;
    cv::Mat smooth;
    cv::sepFilter2D(prev, smooth, CV_32F, kernel, kernel, cv::Point(-1, -1), 0.0,
                    cv::BORDER_REFLECT101);
    cv::Mat down((prev.rows + 1) / 2, (prev.cols + 1) / 2, CV_32F);
    for (int y = 0; y < down.rows; ++y) {
      const float* src = smooth.ptr<float>(2 * y);
      float* dst = down.ptr<float>(y);
      for (int x = 0; x < down.cols; ++x) dst[x] = src[2 * x];
    }
    pyramid.push_back(down);
  }
  return pyramid;
}

cv::Mat DenseLucasKanade(const cv::Mat& first, const cv::Mat& second, const DenseLkOptions& options,
                         std::vector<cv::Mat>* level_flows) {
  options.Validate();
  const auto [a, b] = GreyPair(first, second, "DenseLucasKanade");
  const std::vector<cv::Mat> pa = BuildPyramid(a, options.levels);
  const std::vector<cv::Mat> pb = BuildPyramid(b, options.levels);
  if (level_flows != nullptr) level_flows->clear();
  const cv::Size win(options.window, options.window);
  cv::Mat flow;
  for (int l = static_cast<int>(pa.size()) - 1; l >= 0; --l) {
    const cv::Mat& i0 = pa[static_cast<std::size_t>(l)];
    const cv::Mat& i1 = pb[static_cast<std::size_t>(l)];
    if (flow.empty()) {
      flow = cv::Mat::zeros(i0.size(), CV_32FC2);
    } else {
      // Expand the coarser flow to this level: twice the size, twice the vectors.
      cv::Mat up;
      cv::resize(flow, up, i0.size(), 0, 0, cv::INTER_LINEAR);
      flow = up * 2.0;
    }
    cv::Mat ix, iy;
    cv::Sobel(i0, ix, CV_32F, 1, 0, 3, 1.0 / 8.0, 0.0, cv::BORDER_REFLECT101);
    cv::Sobel(i0, iy, CV_32F, 0, 1, 3, 1.0 / 8.0, 0.0, cv::BORDER_REFLECT101);
    cv::Mat a11, a12, a22;
    cv::boxFilter(ix.mul(ix), a11, CV_32F, win);
    cv::boxFilter(ix.mul(iy), a12, CV_32F, win);
    cv::boxFilter(iy.mul(iy), a22, CV_32F, win);
    cv::Mat map(i0.size(), CV_32FC2);
    for (int it = 0; it < options.iterations; ++it) {
      for (int y = 0; y < map.rows; ++y) {
        const auto* f = flow.ptr<cv::Vec2f>(y);
        auto* m = map.ptr<cv::Vec2f>(y);
        for (int x = 0; x < map.cols; ++x) m[x] = cv::Vec2f(x + f[x][0], y + f[x][1]);
      }
      cv::Mat warped;
      cv::remap(i1, warped, map, cv::noArray(), cv::INTER_LINEAR, cv::BORDER_REPLICATE);
      const cv::Mat it_img = warped - i0;
      cv::Mat b1, b2;
      cv::boxFilter(ix.mul(it_img), b1, CV_32F, win);
      cv::boxFilter(iy.mul(it_img), b2, CV_32F, win);
      SolveAndAdd(a11, a12, a22, b1, b2, options.min_eigen, &flow);
    }
    if (options.median) {
      std::vector<cv::Mat> uv;
      cv::split(flow, uv);
      for (cv::Mat& c : uv) cv::medianBlur(c, c, 3);
      cv::merge(uv, flow);
    }
    if (level_flows != nullptr) level_flows->insert(level_flows->begin(), flow.clone());
  }
  return flow;
}

cv::Mat ComputeFlow(const cv::Mat& first, const cv::Mat& second, const FlowOptions& options) {
  options.Validate();
  const auto [a, b] = GreyPair(first, second, "ComputeFlow");
  cv::Mat flow;
  switch (options.method) {
    case FlowMethod::kDisFast:
    case FlowMethod::kDisMedium: {
      const auto dis = cv::DISOpticalFlow::create(options.method == FlowMethod::kDisFast
                                                      ? cv::DISOpticalFlow::PRESET_FAST
                                                      : cv::DISOpticalFlow::PRESET_MEDIUM);
      if (options.dis_max_flow_width_px > 0) {
        int scale = 0;
        while ((a.cols >> scale) > options.dis_max_flow_width_px) ++scale;
        dis->setFinestScale(scale);
      }
      dis->calc(a, b, flow);
      break;
    }
    case FlowMethod::kFarneback:
      cv::calcOpticalFlowFarneback(a, b, flow, 0.5, 4, 15, 3, 5, 1.1, 0);
      break;
    case FlowMethod::kDenseLk:
      flow = DenseLucasKanade(a, b, options.lk);
      break;
  }
  return flow;
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
