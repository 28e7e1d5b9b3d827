#include "mapless/appearance/image.h"

#include <opencv2/imgproc.hpp>

#include "mapless/core/check.h"

namespace mapless::appearance {

void AppearanceImageOptions::Validate() const {
  MAPLESS_CHECK(width >= 8 && width <= 1024,
                "AppearanceImageOptions.width = " << width << "; must be in [8, 1024]");
  MAPLESS_CHECK(height >= 8 && height <= 1024,
                "AppearanceImageOptions.height = " << height << "; must be in [8, 1024]");
}

cv::Mat LowResolution(const cv::Mat& image, const AppearanceImageOptions& options) {
  options.Validate();
  MAPLESS_CHECK(!image.empty(), "appearance: empty image");
  MAPLESS_CHECK(image.channels() == 1 || image.channels() == 3 || image.channels() == 4,
                "appearance: image with " << image.channels() << " channels");
  cv::Mat gray;
  if (image.channels() == 3) {
    cv::cvtColor(image, gray, cv::COLOR_BGR2GRAY);
  } else if (image.channels() == 4) {
    cv::cvtColor(image, gray, cv::COLOR_BGRA2GRAY);
  } else {
    gray = image;
  }
  cv::Mat small;
  cv::resize(gray, small, cv::Size(options.width, options.height), 0, 0, cv::INTER_AREA);
  cv::Mat out;
  small.convertTo(out, CV_32F);
  if (options.normalize) {
    cv::Scalar mean;
    cv::Scalar stddev;
    cv::meanStdDev(out, mean, stddev);
    const double scale = stddev[0] > 1e-6 ? 1.0 / stddev[0] : 0.0;
    out.convertTo(out, CV_32F, scale, -mean[0] * scale);
  }
  return out;
}

Vector ToVector(const cv::Mat& low_resolution) {
  MAPLESS_CHECK(low_resolution.type() == CV_32FC1, "appearance: expected a CV_32FC1 image");
  const cv::Mat continuous =
      low_resolution.isContinuous() ? low_resolution : low_resolution.clone();
  return Eigen::Map<const Vector>(continuous.ptr<float>(), continuous.rows * continuous.cols);
}

Vector AppearanceVector(const cv::Mat& image, const AppearanceImageOptions& options) {
  return ToVector(LowResolution(image, options));
}

}  // namespace mapless::appearance
