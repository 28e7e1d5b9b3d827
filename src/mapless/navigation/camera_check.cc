#include "mapless/navigation/camera_check.h"

#include <cmath>
#include <iomanip>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "mapless/core/check.h"

namespace mapless::navigation {
namespace {

std::string Fixed(double value, int digits) {
  std::ostringstream out;
  out << std::fixed << std::setprecision(digits) << value;
  return out.str();
}

CameraCheck Fault(CameraFault fault, const std::string& detail) {
  return {fault, std::string("camera fault: ") + CameraFaultName(fault) + " (" + detail + ")"};
}

}  // namespace

void CameraCheckOptions::Validate() const {
  if (!(black_mean >= 0.0 && black_mean < 255.0))
    throw InputError("camera.black_mean must be in [0, 255)");
  if (!(saturated_level > 0.0 && saturated_level <= 255.0))
    throw InputError("camera.saturated_level must be in (0, 255]");
  if (!(max_saturated_fraction > 0.0 && max_saturated_fraction <= 1.0))
    throw InputError("camera.max_saturated_fraction must be in (0, 1]");
  if (!(min_stddev >= 0.0)) throw InputError("camera.min_stddev must be >= 0");
  if (!(moving_speed_mps >= 0.0 && moving_rate_radps >= 0.0))
    throw InputError("camera.moving_speed_mps and moving_rate_radps must be >= 0");
}

const char* CameraFaultName(CameraFault f) {
  switch (f) {
    case CameraFault::kNone:
      return "none";
    case CameraFault::kNoImage:
      return "no image";
    case CameraFault::kBlack:
      return "black frame";
    case CameraFault::kOverExposed:
      return "over-exposed";
    case CameraFault::kFeatureless:
      return "featureless view";
    case CameraFault::kFrozen:
      return "frozen camera";
  }
  return "unknown";
}

CameraMonitor::CameraMonitor(CameraCheckOptions options) : options_(options) {
  options_.Validate();
}

CameraCheck CameraMonitor::Check(const cv::Mat& image, const Twist2& last_command) {
  if (image.empty()) {
    previous_.release();
    frozen_ = false;
    return Fault(CameraFault::kNoImage, "the source delivered no frame");
  }
  cv::Mat grey = image;
  if (image.channels() == 3) cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  if (grey.depth() != CV_8U) {
    return Fault(CameraFault::kNoImage,
                 "expected 8-bit images, got OpenCV depth " + std::to_string(grey.depth()));
  }

  const bool told_to_move = std::abs(last_command.v_mps) > options_.moving_speed_mps ||
                            std::abs(last_command.omega_radps) > options_.moving_rate_radps;
  const bool moving = told_to_move && was_moving_;
  was_moving_ = told_to_move;
  const bool same = !previous_.empty() && previous_.size() == grey.size() &&
                    cv::norm(previous_, grey, cv::NORM_INF) == 0.0;
  if (!same) frozen_ = false;
  if (same && moving) frozen_ = true;
  if (!same) grey.copyTo(previous_);
  if (frozen_) return Fault(CameraFault::kFrozen, "the same image again while the robot moves");

  cv::Scalar mean;
  cv::Scalar stddev;
  cv::meanStdDev(grey, mean, stddev);
  if (mean[0] <= options_.black_mean) {
    return Fault(CameraFault::kBlack, "mean grey level " + Fixed(mean[0], 1));
  }
  const double saturated = static_cast<double>(cv::countNonZero(grey >= options_.saturated_level)) /
                           static_cast<double>(grey.total());
  if (saturated > options_.max_saturated_fraction) {
    return Fault(CameraFault::kOverExposed,
                 Fixed(100.0 * saturated, 0) + "% of the pixels saturated");
  }
  if (stddev[0] < options_.min_stddev) {
    return Fault(CameraFault::kFeatureless, "grey-level standard deviation " + Fixed(stddev[0], 2));
  }
  return {};
}

}  // namespace mapless::navigation
