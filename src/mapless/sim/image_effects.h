// Camera image degradations used by the papers' experiments: Gaussian noise, salt-and-pepper
// inversion of a fraction of the pixels (the papers use 20%), a global brightness/contrast change,
// and blur. Deterministic: the caller passes a seeded generator.
#pragma once

#include <opencv2/core.hpp>

#include "mapless/core/rng.h"

namespace mapless::sim {

struct ImageEffects {
  double noise_sigma = 0.0;      // Gaussian noise, standard deviation in grey levels
  double invert_fraction = 0.0;  // fraction of pixels inverted (v -> 255 - v), 0..1
  double gain = 1.0;             // contrast: out = gain * (in - 128) + 128 + bias
  double bias = 0.0;             // brightness offset, grey levels
  double blur_sigma_px = 0.0;    // Gaussian blur, pixels

  bool Any() const {
    return noise_sigma > 0.0 || invert_fraction > 0.0 || gain != 1.0 || bias != 0.0 ||
           blur_sigma_px > 0.0;
  }
  void Validate() const;  // throws InputError naming the field
};

// Applies the effects in the order blur, gain/bias, noise, inversion; returns a new image.
cv::Mat ApplyEffects(const cv::Mat& image, const ImageEffects& effects, Rng* rng);

}  // namespace mapless::sim
