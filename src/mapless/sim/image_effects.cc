#include "mapless/sim/image_effects.h"

#include <opencv2/imgproc.hpp>

#include "mapless/core/check.h"

namespace mapless::sim {

void ImageEffects::Validate() const {
  MAPLESS_CHECK(noise_sigma >= 0.0 && noise_sigma <= 255.0,
                "ImageEffects.noise_sigma = " << noise_sigma << "; must be in [0, 255]");
  MAPLESS_CHECK(invert_fraction >= 0.0 && invert_fraction <= 1.0,
                "ImageEffects.invert_fraction = " << invert_fraction << "; must be in [0, 1]");
  MAPLESS_CHECK(gain >= 0.0 && gain <= 100.0,
                "ImageEffects.gain = " << gain << "; must be in [0, 100]");
  MAPLESS_CHECK(bias >= -255.0 && bias <= 255.0,
                "ImageEffects.bias = " << bias << "; must be in [-255, 255]");
  MAPLESS_CHECK(blur_sigma_px >= 0.0 && blur_sigma_px <= 20.0,
                "ImageEffects.blur_sigma_px = " << blur_sigma_px << "; must be in [0, 20]");
}

cv::Mat ApplyEffects(const cv::Mat& image, const ImageEffects& effects, Rng* rng) {
  CV_Assert(image.type() == CV_8UC1);
  cv::Mat out = image.clone();
  if (effects.blur_sigma_px > 0.0) {
    cv::GaussianBlur(out, out, cv::Size(0, 0), effects.blur_sigma_px, effects.blur_sigma_px,
                     cv::BORDER_REFLECT101);
  }
  const bool tone = effects.gain != 1.0 || effects.bias != 0.0;
  if (tone || effects.noise_sigma > 0.0) {
    for (int y = 0; y < out.rows; ++y) {
      auto* row = out.ptr<std::uint8_t>(y);
      for (int x = 0; x < out.cols; ++x) {
        double v = row[x];
        if (tone) v = effects.gain * (v - 128.0) + 128.0 + effects.bias;
        if (effects.noise_sigma > 0.0) v += effects.noise_sigma * rng->Normal();
        row[x] = cv::saturate_cast<std::uint8_t>(v);
      }
    }
  }
  if (effects.invert_fraction > 0.0) {
    for (int y = 0; y < out.rows; ++y) {
      auto* row = out.ptr<std::uint8_t>(y);
      for (int x = 0; x < out.cols; ++x) {
        if (rng->Uniform() < effects.invert_fraction)
          row[x] = static_cast<std::uint8_t>(255 - row[x]);
      }
    }
  }
  return out;
}

}  // namespace mapless::sim
