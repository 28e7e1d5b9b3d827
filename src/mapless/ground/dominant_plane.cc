#include "mapless/ground/dominant_plane.h"

#include <algorithm>
#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "mapless/core/check.h"

namespace mapless::ground {
namespace {

cv::Rect RoiOf(cv::Size size, double top_fraction) {
  const int top =
      std::clamp(static_cast<int>(std::lround(top_fraction * size.height)), 0, size.height - 1);
  return {0, top, size.width, size.height - top};
}

// Keeps the 255-regions of `mask` that touch its bottom row.
cv::Mat BottomConnected(const cv::Mat& mask) {
  cv::Mat labels;
  const int n = cv::connectedComponents(mask, labels, 4, CV_32S);
  std::vector<uchar> keep(static_cast<std::size_t>(n), 0);
  const int* bottom = labels.ptr<int>(labels.rows - 1);
  for (int x = 0; x < labels.cols; ++x)
    if (bottom[x] > 0) keep[static_cast<std::size_t>(bottom[x])] = 255;
  cv::Mat out(mask.size(), CV_8UC1);
  for (int y = 0; y < mask.rows; ++y) {
    const int* l = labels.ptr<int>(y);
    uchar* o = out.ptr<uchar>(y);
    for (int x = 0; x < mask.cols; ++x) o[x] = keep[static_cast<std::size_t>(l[x])];
  }
  return out;
}

}  // namespace

PlaneModel ParsePlaneModel(const std::string& name) {
  if (name == "affine") return PlaneModel::kAffine;
  if (name == "homography") return PlaneModel::kHomography;
  throw InputError("unknown plane model '" + name + "' (known: affine, homography)");
}

const char* PlaneModelName(PlaneModel model) {
  return model == PlaneModel::kAffine ? "affine" : "homography";
}

void DominantPlaneOptions::Validate() const {
  MAPLESS_CHECK(epsilon_px > 0.0,
                "DominantPlaneOptions.epsilon_px = " << epsilon_px << "; must be > 0");
  MAPLESS_CHECK(
      nearer_fraction > 0.0 && nearer_fraction <= 1.0,
      "DominantPlaneOptions.nearer_fraction = " << nearer_fraction << "; must be in (0, 1]");
  MAPLESS_CHECK(epsilon_relative >= 0.0,
                "DominantPlaneOptions.epsilon_relative = " << epsilon_relative << "; must be >= 0");
  MAPLESS_CHECK(
      sample_step_px >= 1 && sample_step_px <= 64,
      "DominantPlaneOptions.sample_step_px = " << sample_step_px << "; must be in [1, 64]");
  MAPLESS_CHECK(confidence > 0.0 && confidence < 1.0,
                "DominantPlaneOptions.confidence = " << confidence << "; must be in (0, 1)");
  MAPLESS_CHECK(fit_bottom_fraction > 0.0 && fit_bottom_fraction <= 1.0,
                "DominantPlaneOptions.fit_bottom_fraction = " << fit_bottom_fraction
                                                              << "; must be in (0, 1]");
  MAPLESS_CHECK(max_iterations >= 0, "DominantPlaneOptions.max_iterations = "
                                         << max_iterations << "; must be >= 0 (0: the paper's)");
  MAPLESS_CHECK(
      roi_top_fraction >= 0.0 && roi_top_fraction < 1.0,
      "DominantPlaneOptions.roi_top_fraction = " << roi_top_fraction << "; must be in [0, 1)");
  MAPLESS_CHECK(
      min_plane_fraction >= 0.0 && min_plane_fraction < 1.0,
      "DominantPlaneOptions.min_plane_fraction = " << min_plane_fraction << "; must be in [0, 1)");
  MAPLESS_CHECK(open_px >= 0 && open_px <= 10,
                "DominantPlaneOptions.open_px = " << open_px << "; must be in [0, 10]");
}

cv::Mat PlanarFlow(const cv::Mat& model, cv::Size size) {
  MAPLESS_CHECK(model.rows == 3 && model.cols == 3 && model.type() == CV_64F,
                "PlanarFlow: the model must be a 3x3 CV_64F matrix");
  cv::Mat out(size, CV_32FC2);
  const auto* m = model.ptr<double>();
  for (int y = 0; y < size.height; ++y) {
    auto* o = out.ptr<cv::Vec2f>(y);
    for (int x = 0; x < size.width; ++x) {
      const double w = m[6] * x + m[7] * y + m[8];
      const double s = std::abs(w) > 1e-12 ? 1.0 / w : 0.0;
      o[x] = cv::Vec2f(static_cast<float>((m[0] * x + m[1] * y + m[2]) * s - x),
                       static_cast<float>((m[3] * x + m[4] * y + m[5]) * s - y));
    }
  }
  return out;
}

DominantPlane DetectDominantPlane(const cv::Mat& flow, const DominantPlaneOptions& options) {
  options.Validate();
  MAPLESS_CHECK(flow.type() == CV_32FC2 && !flow.empty(),
                "DetectDominantPlane: the flow must be a non-empty CV_32FC2 field");
  DominantPlane result;
  result.mask = cv::Mat::zeros(flow.size(), CV_8UC1);
  const cv::Rect roi = RoiOf(flow.size(), options.roi_top_fraction);
  std::vector<cv::Point2f> from, to;
  const int fit_top =
      roi.y + static_cast<int>(std::floor(roi.height * (1.0 - options.fit_bottom_fraction)));
  for (int y = fit_top + options.sample_step_px / 2; y < roi.y + roi.height;
       y += options.sample_step_px) {
    const auto* f = flow.ptr<cv::Vec2f>(y);
    for (int x = options.sample_step_px / 2; x < flow.cols; x += options.sample_step_px) {
      if (!std::isfinite(f[x][0]) || !std::isfinite(f[x][1])) continue;
      from.emplace_back(static_cast<float>(x), static_cast<float>(y));
      to.emplace_back(static_cast<float>(x) + f[x][0], static_cast<float>(y) + f[x][1]);
    }
  }
  const int minimal = options.model == PlaneModel::kAffine ? 3 : 4;
  if (static_cast<int>(from.size()) < 2 * minimal) return result;
  // The paper iterates at most width * height / 2 times; the adaptive count stops far earlier.
  const int max_iterations = options.max_iterations > 0 ? options.max_iterations
                                                        : std::max(100, flow.cols * flow.rows / 2);
  std::vector<uchar> inliers;
  cv::Mat model;
  if (options.model == PlaneModel::kAffine) {
    const cv::Mat a =
        cv::estimateAffine2D(from, to, inliers, cv::RANSAC, options.epsilon_px,
                             static_cast<std::size_t>(max_iterations), options.confidence, 10);
    if (!a.empty()) {
      model = cv::Mat::eye(3, 3, CV_64F);
      a.copyTo(model.rowRange(0, 2));
    }
  } else {
    model = cv::findHomography(from, to, cv::RANSAC, options.epsilon_px, inliers, max_iterations,
                               options.confidence);
  }
  if (model.empty()) return result;
  result.model = model;
  const double w =
      static_cast<double>(std::count(inliers.begin(), inliers.end(), 1)) / inliers.size();
  result.iterations =
      w >= 1.0 ? 1
               : std::min(max_iterations,
                          static_cast<int>(std::ceil(std::log(1.0 - options.confidence) /
                                                     std::log(1.0 - std::pow(w, minimal)))));
  // Eq. 5 on every pixel: on the plane when the flow agrees with the planar flow (computed
  // inline, as PlanarFlow does, without materialising the field).
  const auto* m = model.ptr<double>();
  const auto eps = static_cast<float>(options.epsilon_px);
  const auto rel = static_cast<float>(options.epsilon_relative);
  const auto nearer = static_cast<float>(options.nearer_fraction);
  for (int y = 0; y < flow.rows; ++y) {
    const auto* f = flow.ptr<cv::Vec2f>(y);
    uchar* d = result.mask.ptr<uchar>(y);
    // Per row, the homography's numerators and denominator are affine in x: float steps.
    const auto a0 = static_cast<float>(m[1] * y + m[2]);
    const auto b0 = static_cast<float>(m[4] * y + m[5]);
    const auto w0 = static_cast<float>(m[7] * y + m[8]);
    const auto a1 = static_cast<float>(m[0]);
    const auto b1 = static_cast<float>(m[3]);
    const auto w1 = static_cast<float>(m[6]);
    const auto fy = static_cast<float>(y);
    for (int x = 0; x < flow.cols; ++x) {
      const auto fx = static_cast<float>(x);
      const float h = w1 * fx + w0;
      const float s = std::abs(h) > 1e-12F ? 1.0F / h : 0.0F;
      const float px = (a1 * fx + a0) * s - fx;
      const float py = (b1 * fx + b0) * s - fy;
      const float du = f[x][0] - px;
      const float dv = f[x][1] - py;
      const float norm = std::sqrt(px * px + py * py);
      const float tol = eps + rel * norm;
      // The excess along the planar flow's direction: > 0 where the pixel moves more than the
      // ground there would, i.e. is nearer (something standing on the ground).
      const float along = norm > 1e-6F ? (du * px + dv * py) / norm : 0.0F;
      d[x] = du * du + dv * dv < tol * tol && along < nearer * tol ? 255 : 0;
    }
  }
  if (options.open_px > 0) {
    const cv::Mat k = cv::getStructuringElement(
        cv::MORPH_ELLIPSE, cv::Size(2 * options.open_px + 1, 2 * options.open_px + 1));
    cv::morphologyEx(result.mask, result.mask, cv::MORPH_OPEN, k);
  }
  if (options.bottom_connected) result.mask = BottomConnected(result.mask);
  result.roi_fraction = static_cast<double>(cv::countNonZero(result.mask(roi))) / roi.area();
  result.found = result.roi_fraction > options.min_plane_fraction;
  if (!result.found) result.mask.setTo(0);
  return result;
}

double InclusionMeasure(const cv::Mat& a, const cv::Mat& b) {
  cv::Mat bb = b;
  if (b.size() != a.size()) cv::resize(b, bb, a.size(), 0, 0, cv::INTER_NEAREST);
  const int nb = cv::countNonZero(bb);
  if (nb == 0) return 1.0;
  cv::Mat both;
  cv::bitwise_and(a, bb, both);
  return static_cast<double>(cv::countNonZero(both)) / nb;
}

HierarchicalPlanes DetectHierarchicalPlanes(const std::vector<cv::Mat>& layer_flows,
                                            const DominantPlaneOptions& options) {
  HierarchicalPlanes out;
  for (std::size_t l = 0; l < layer_flows.size(); ++l) {
    DominantPlaneOptions o = options;
    // A pixel of layer l is 2^l pixels of the image: scale the tolerance with it.
    o.epsilon_px = options.epsilon_px / static_cast<double>(1 << l);
    o.sample_step_px = std::max(1, options.sample_step_px >> l);
    o.open_px = l == 0 ? options.open_px : 0;
    out.layers.push_back(DetectDominantPlane(layer_flows[l], o));
  }
  for (std::size_t l = 0; l + 1 < out.layers.size(); ++l)
    out.inclusion.push_back(InclusionMeasure(out.layers[l].mask, out.layers[l + 1].mask));
  return out;
}

double MaskIoU(const cv::Mat& a, const cv::Mat& b, const cv::Rect& roi) {
  MAPLESS_CHECK(a.size() == b.size() && a.type() == CV_8UC1 && b.type() == CV_8UC1,
                "MaskIoU: masks must be CV_8UC1 of the same size");
  const cv::Rect r = roi.area() > 0 ? roi : cv::Rect(0, 0, a.cols, a.rows);
  cv::Mat inter, uni;
  cv::bitwise_and(a(r), b(r), inter);
  cv::bitwise_or(a(r), b(r), uni);
  const int nu = cv::countNonZero(uni);
  return nu == 0 ? 1.0 : static_cast<double>(cv::countNonZero(inter)) / nu;
}

}  // namespace mapless::ground
