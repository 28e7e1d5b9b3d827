#include "mapless/sim/image_effects.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "mapless/core/check.h"

namespace mapless::sim {
namespace {

cv::Mat Ramp() {
  cv::Mat img(60, 80, CV_8UC1);
  for (int y = 0; y < img.rows; ++y) {
    for (int x = 0; x < img.cols; ++x)
      img.at<std::uint8_t>(y, x) = static_cast<std::uint8_t>(40 + 2 * x);
  }
  return img;
}

TEST(ImageEffects, NoEffectsLeaveTheImageUnchanged) {
  Rng rng(1);
  const cv::Mat in = Ramp();
  EXPECT_EQ(cv::norm(in, ApplyEffects(in, ImageEffects{}, &rng), cv::NORM_INF), 0.0);
}

TEST(ImageEffects, GainAndBiasChangeContrastAndBrightness) {
  Rng rng(1);
  ImageEffects e;
  e.gain = 0.5;
  e.bias = 20.0;
  const cv::Mat out = ApplyEffects(Ramp(), e, &rng);
  // 0.5 * (v - 128) + 128 + 20 at v = 40 and v = 198.
  EXPECT_EQ(out.at<std::uint8_t>(0, 0), 104);
  EXPECT_EQ(out.at<std::uint8_t>(0, 79), 183);
}

TEST(ImageEffects, GaussianNoiseHasTheRequestedSpread) {
  Rng rng(3);
  ImageEffects e;
  e.noise_sigma = 6.0;
  const cv::Mat flat(200, 200, CV_8UC1, cv::Scalar(128));
  cv::Scalar mean, sd;
  cv::meanStdDev(ApplyEffects(flat, e, &rng), mean, sd);
  EXPECT_NEAR(mean[0], 128.0, 0.2);
  EXPECT_NEAR(sd[0], 6.0, 0.3);
}

TEST(ImageEffects, InversionFlipsTheRequestedFractionOfPixels) {
  Rng rng(4);
  ImageEffects e;
  e.invert_fraction = 0.2;
  const cv::Mat dark(200, 200, CV_8UC1, cv::Scalar(10));
  const cv::Mat out = ApplyEffects(dark, e, &rng);
  const double inverted = cv::countNonZero(out == 245) / static_cast<double>(out.total());
  EXPECT_NEAR(inverted, 0.2, 0.01);
  EXPECT_EQ(cv::countNonZero((out != 245) & (out != 10)), 0);
}

TEST(ImageEffects, BlurSmoothsAStepEdge) {
  Rng rng(1);
  ImageEffects e;
  e.blur_sigma_px = 2.0;
  cv::Mat step(20, 40, CV_8UC1, cv::Scalar(0));
  step(cv::Rect(20, 0, 20, 20)).setTo(200);
  const cv::Mat out = ApplyEffects(step, e, &rng);
  EXPECT_GT(out.at<std::uint8_t>(10, 19), 40);
  EXPECT_LT(out.at<std::uint8_t>(10, 20), 160);
}

TEST(ImageEffects, InvalidValuesNameTheField) {
  ImageEffects e;
  e.invert_fraction = 1.5;
  try {
    e.Validate();
    FAIL();
  } catch (const InputError& err) {
    EXPECT_NE(std::string(err.what()).find("ImageEffects.invert_fraction = 1.5"),
              std::string::npos);
  }
}

}  // namespace
}  // namespace mapless::sim
