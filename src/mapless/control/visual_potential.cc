#include "mapless/control/visual_potential.h"

#include <cmath>
#include <opencv2/imgproc.hpp>

#include "mapless/core/check.h"

namespace mapless::control {

void VisualPotentialOptions::Validate() const {
  MAPLESS_CHECK(
      sigma_fraction > 0.0 && sigma_fraction <= 2.0,
      "VisualPotentialOptions.sigma_fraction = " << sigma_fraction << "; must be in (0, 2]");
  MAPLESS_CHECK(
      work_width_px >= 16 && work_width_px <= 4096,
      "VisualPotentialOptions.work_width_px = " << work_width_px << "; must be in [16, 4096]");
  MAPLESS_CHECK(repulsion_gain >= 0.0,
                "VisualPotentialOptions.repulsion_gain = " << repulsion_gain << "; must be >= 0");
  MAPLESS_CHECK(max_translation_mps >= 0.0 && max_rotation_radps >= 0.0,
                "VisualPotentialOptions: T_m and R_m must be >= 0");
}

cv::Mat RepulsionField(const cv::Mat& plane_mask, const VisualPotentialOptions& options) {
  options.Validate();
  MAPLESS_CHECK(plane_mask.type() == CV_8UC1 && !plane_mask.empty(),
                "RepulsionField: the dominant-plane map must be a non-empty CV_8UC1 image");
  const double scale = std::min(1.0, static_cast<double>(options.work_width_px) / plane_mask.cols);
  cv::Mat d;
  plane_mask.convertTo(d, CV_32F);
  cv::Mat small = d;
  if (scale < 1.0) cv::resize(d, small, cv::Size(), scale, scale, cv::INTER_AREA);
  // Sigma is half the image size at full resolution; in the small map's pixels it scales too.
  const double sigma = options.sigma_fraction * plane_mask.cols * scale;
  cv::Mat smooth;
  cv::GaussianBlur(small, smooth, cv::Size(0, 0), sigma, sigma, cv::BORDER_REPLICATE);
  cv::Mat gx, gy;
  cv::Sobel(smooth, gx, CV_32F, 1, 0, 3, 1.0 / 8.0, 0.0, cv::BORDER_REPLICATE);
  cv::Sobel(smooth, gy, CV_32F, 0, 1, 3, 1.0 / 8.0, 0.0, cv::BORDER_REPLICATE);
  // Back to full-resolution pixels: a gradient per small pixel is scale times one per pixel.
  cv::Mat g;
  cv::merge(std::vector<cv::Mat>{gx * scale, gy * scale}, g);
  if (scale < 1.0) cv::resize(g, g, plane_mask.size(), 0, 0, cv::INTER_LINEAR);
  return g;
}

cv::Mat DesiredFlow(const cv::Mat& translational, const cv::Mat& rotational, double theta_d_rad) {
  MAPLESS_CHECK(translational.type() == CV_32FC2 && rotational.type() == CV_32FC2 &&
                    translational.size() == rotational.size(),
                "DesiredFlow: the pure flows must be CV_32FC2 fields of the same size");
  return translational * std::cos(theta_d_rad) + rotational * std::sin(theta_d_rad);
}

cv::Mat PotentialField(const cv::Mat& plane_mask, const cv::Mat& repulsion,
                       const cv::Mat& attraction, const VisualPotentialOptions& options) {
  MAPLESS_CHECK(plane_mask.size() == repulsion.size() && repulsion.size() == attraction.size() &&
                    repulsion.type() == CV_32FC2 && attraction.type() == CV_32FC2,
                "PotentialField: map, repulsion and attraction must have the same size");
  const auto gain = static_cast<float>(options.repulsion_gain);
  cv::Mat p(plane_mask.size(), CV_32FC2);
  for (int y = 0; y < p.rows; ++y) {
    const uchar* d = plane_mask.ptr<uchar>(y);
    const auto* g = repulsion.ptr<cv::Vec2f>(y);
    const auto* u = attraction.ptr<cv::Vec2f>(y);
    auto* o = p.ptr<cv::Vec2f>(y);
    for (int x = 0; x < p.cols; ++x) o[x] = d[x] == 255 ? gain * g[x] - u[x] : gain * g[x];
  }
  return p;
}

cv::Vec2d ControlForce(const cv::Mat& potential, const cv::Rect& roi) {
  MAPLESS_CHECK(potential.type() == CV_32FC2 && !potential.empty(),
                "ControlForce: the potential must be a non-empty CV_32FC2 field");
  const cv::Rect r = roi.area() > 0 ? roi & cv::Rect(0, 0, potential.cols, potential.rows)
                                    : cv::Rect(0, 0, potential.cols, potential.rows);
  const cv::Scalar m = cv::mean(potential(r));
  return {m[0], m[1]};
}

PotentialCommand CommandFromForce(const cv::Vec2d& force, const VisualPotentialOptions& options) {
  PotentialCommand c;
  if (std::hypot(force[0], force[1]) < 1e-12) return c;  // no force: stand still
  c.theta_rad = std::atan2(-force[0], -force[1]);        // from (0, -1), positive to the left
  c.twist.v_mps = options.max_translation_mps * std::cos(c.theta_rad);
  c.twist.omega_radps = options.max_rotation_radps * std::sin(c.theta_rad);
  return c;
}

}  // namespace mapless::control
