// Image preprocessing for appearance-based navigation: the camera image is reduced to a small
// grayscale image (64x64 by default, Section 2 of Payá et al.) and, by default, normalised to zero
// mean and unit variance so that a global change of brightness or exposure does not move it in the
// eigenspace (not in the paper; conventional for appearance-based localization; off with
// `normalize = false`).
#pragma once

#include <opencv2/core.hpp>

#include "mapless/appearance/pca.h"

namespace mapless::appearance {

struct AppearanceImageOptions {
  int width = 64;         // low-resolution image width, px
  int height = 64;        // low-resolution image height, px
  bool normalize = true;  // zero mean, unit standard deviation per image
  void Validate() const;
};

// The low-resolution image as CV_32FC1 (area interpolation; colour converted to gray), normalised
// when the options say so. Throws InputError for an empty image.
cv::Mat LowResolution(const cv::Mat& image, const AppearanceImageOptions& options);

// The low-resolution image as one column vector (row-major pixels).
Vector ToVector(const cv::Mat& low_resolution);

// LowResolution then ToVector.
Vector AppearanceVector(const cv::Mat& image, const AppearanceImageOptions& options);

}  // namespace mapless::appearance
