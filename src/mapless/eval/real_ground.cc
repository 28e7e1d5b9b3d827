#include "mapless/eval/real_ground.h"

#include <algorithm>
#include <filesystem>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>

#include "mapless/core/check.h"
#include "mapless/eval/real_common.h"
#include "mapless/io/image_file.h"

namespace mapless::eval {
namespace {

namespace fs = std::filesystem;
constexpr int kBaselineGridPx = 4;

// The stock baseline: cv::findHomography with RANSAC on the flow's correspondences (a 4 px grid in
// the region of interest); the ground is every pixel of the region whose flow the homography
// predicts within the same threshold.
cv::Mat RansacHomographyGround(const cv::Mat& field, int roi_top, double threshold_px) {
  std::vector<cv::Point2f> from, to;
  for (int y = roi_top; y < field.rows; y += kBaselineGridPx) {
    for (int x = 0; x < field.cols; x += kBaselineGridPx) {
      const cv::Point2f u = field.at<cv::Point2f>(y, x);
      from.emplace_back(static_cast<float>(x), static_cast<float>(y));
      to.emplace_back(static_cast<float>(x) + u.x, static_cast<float>(y) + u.y);
    }
  }
  cv::Mat mask = cv::Mat::zeros(field.size(), CV_8U);
  if (from.size() < 4) return mask;
  cv::setRNGSeed(1);  // deterministic
  const cv::Mat h = cv::findHomography(from, to, cv::RANSAC, threshold_px);
  if (h.empty()) return mask;
  const cv::Mat planar = ground::PlanarFlow(h, field.size());
  for (int y = roi_top; y < field.rows; ++y) {
    for (int x = 0; x < field.cols; ++x) {
      const cv::Point2f d = field.at<cv::Point2f>(y, x) - planar.at<cv::Point2f>(y, x);
      if (d.x * d.x + d.y * d.y <= threshold_px * threshold_px) mask.at<uchar>(y, x) = 255;
    }
  }
  return mask;
}

}  // namespace

GroundEvalOptions DefaultGroundEvalOptions() {
  GroundEvalOptions o;
  o.flow.method = flow::FlowMethod::kDisMedium;
  o.plane.model = ground::PlaneModel::kHomography;
  o.plane.epsilon_px = 0.4;
  o.plane.epsilon_relative = 0.4;
  o.plane.nearer_fraction = 0.5;
  o.plane.roi_top_fraction = 0.5;
  o.plane.fit_bottom_fraction = 0.5;
  return o;
}

GroundEvalFigures EvalGround(const std::string& frames_dir, const std::string& masks_dir,
                             const GroundEvalOptions& options) {
  options.plane.Validate();
  MAPLESS_CHECK(options.iou_top_fraction >= 0.0 && options.iou_top_fraction < 1.0,
                "IoU region top " << options.iou_top_fraction << ": must be in [0, 1)");
  const std::vector<std::string> frames = ImageNamesIn(frames_dir, "--frames");
  MAPLESS_CHECK(fs::is_directory(masks_dir), "--masks " << masks_dir << ": not a folder of images");
  // Every frame and mask is read and checked before the work.
  std::vector<cv::Mat> images;
  std::vector<cv::Mat> truth(frames.size());
  double pixels = 0.0;
  for (std::size_t i = 0; i < frames.size(); ++i) {
    images.push_back(io::ReadImage(frames_dir + "/" + frames[i], cv::IMREAD_GRAYSCALE, 16));
    pixels += 2.0 * static_cast<double>(images.back().total());  // the frame and its mask
    MAPLESS_CHECK(pixels <= kMaxHeldPixels,
                  "--frames " << frames_dir << ": more than " << kMaxHeldPixels / 1e6
                              << " megapixels with the masks (at " << frames[i]
                              << "); use fewer or smaller frames");
    if (i > 0)
      io::RequireSameSize(images[i], frames_dir + "/" + frames[i], images[0],
                          frames_dir + "/" + frames[0]);
    const std::string mask = masks_dir + "/" + frames[i];
    if (i + 1 < frames.size() && fs::exists(mask)) {
      truth[i] = io::ReadImage(mask, cv::IMREAD_GRAYSCALE, 16) > 127;
      io::RequireSameSize(truth[i], mask, images[0], frames_dir + "/" + frames[0]);
    }
  }
  GroundEvalFigures out;
  GroundMethodFigures mapless{"mapless"}, baseline{"ransac_homography"};
  std::vector<double> flow_ms, mapless_ms, baseline_ms;
  for (std::size_t i = 0; i + 1 < frames.size(); ++i) {
    if (truth[i].empty()) continue;
    auto start = std::chrono::steady_clock::now();
    const cv::Mat field = flow::ComputeFlow(images[i], images[i + 1], options.flow);
    flow_ms.push_back(MsSince(start));
    const int top = static_cast<int>(options.iou_top_fraction * field.rows);
    const cv::Rect region(0, top, field.cols, field.rows - top);
    start = std::chrono::steady_clock::now();
    const ground::DominantPlane plane = ground::DetectDominantPlane(field, options.plane);
    mapless_ms.push_back(MsSince(start));
    mapless.mean_iou += ground::MaskIoU(plane.mask, truth[i], region);
    ++mapless.pairs;
    if (options.baselines) {
      start = std::chrono::steady_clock::now();
      const int roi_top = static_cast<int>(options.plane.roi_top_fraction * field.rows);
      const cv::Mat mask = RansacHomographyGround(field, roi_top, options.baseline_threshold_px);
      baseline_ms.push_back(MsSince(start));
      baseline.mean_iou += ground::MaskIoU(mask, truth[i], region);
      ++baseline.pairs;
    }
  }
  MAPLESS_CHECK(mapless.pairs > 0, "--masks " << masks_dir << ": no mask has the name of a frame "
                                              << "that has a next frame in " << frames_dir);
  out.pairs = mapless.pairs;
  out.flow_ms = Median(flow_ms);
  mapless.mean_iou /= mapless.pairs;
  mapless.plane_ms = Median(mapless_ms);
  out.methods.push_back(mapless);
  if (options.baselines) {
    baseline.mean_iou /= baseline.pairs;
    baseline.plane_ms = Median(baseline_ms);
    out.methods.push_back(baseline);
  }
  return out;
}

}  // namespace mapless::eval
