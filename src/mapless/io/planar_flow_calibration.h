// The visual potential's planar-flow calibration (Ohnishi & Imiya, Section 4.3) and its file.
//
// The pure translational and rotational planar flows, calibrated by driving at a constant velocity
// (as the paper does), stored as the two fitted ground homographies: the flow at any pixel is
// model(x) - x (ground::PlanarFlow). Both are for one frame period. The file is a small versioned
// YAML document (`mapless navigate --save-calibration`).
#pragma once

#include <opencv2/core.hpp>
#include <string>

namespace mapless::io {

struct PlanarFlowCalibration {
  int width = 0;
  int height = 0;
  double period_s = 0.0;     // frame period of the calibration drive
  double speed_mps = 0.0;    // translation during the translational drive
  double omega_radps = 0.0;  // rotation (counter-clockwise) during the rotational drive
  cv::Mat translational;     // 3x3 CV_64F homography, forward motion
  cv::Mat rotational;        // 3x3 CV_64F homography, counter-clockwise rotation
  void Validate() const;     // throws InputError naming the field
};

// The calibration as YAML text, and back. Parse errors name `source`, the line and the field.
std::string CalibrationToYaml(const PlanarFlowCalibration& calibration);
PlanarFlowCalibration CalibrationFromYaml(const std::string& text, const std::string& source);

}  // namespace mapless::io
