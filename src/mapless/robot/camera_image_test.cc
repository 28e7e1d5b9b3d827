#include "mapless/robot/camera_image.h"

#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "mapless/core/check.h"
#include "mapless/io/lazy_libraries.h"

namespace mapless::robot {
namespace {

std::string Bytes(const cv::Mat& m) {
  return std::string(reinterpret_cast<const char*>(m.data), m.total() * m.elemSize());
}

TEST(CameraImage, ConvertsEveryEncodingToTheSameGrey) {
  cv::Mat bgr(20, 24, CV_8UC3);
  cv::randu(bgr, 0, 255);
  cv::Mat expected;
  cv::cvtColor(bgr, expected, cv::COLOR_BGR2GRAY);
  cv::Mat rgb, bgra;
  cv::cvtColor(bgr, rgb, cv::COLOR_BGR2RGB);
  cv::cvtColor(bgr, bgra, cv::COLOR_BGR2BGRA);
  EXPECT_EQ(cv::norm(GreyFromRaw("bgr8", 24, 20, 72, false, Bytes(bgr)), expected, cv::NORM_INF),
            0);
  EXPECT_EQ(cv::norm(GreyFromRaw("rgb8", 24, 20, 72, false, Bytes(rgb)), expected, cv::NORM_INF),
            0);
  EXPECT_LE(cv::norm(GreyFromRaw("bgra8", 24, 20, 96, false, Bytes(bgra)), expected, cv::NORM_INF),
            1);
  EXPECT_EQ(
      cv::norm(GreyFromRaw("mono8", 24, 20, 24, false, Bytes(expected)), expected, cv::NORM_INF),
      0);
  cv::Mat wide;
  expected.convertTo(wide, CV_16U, 256.0);
  EXPECT_EQ(cv::norm(GreyFromRaw("mono16", 24, 20, 48, false, Bytes(wide)), expected, cv::NORM_INF),
            0);
  // A padded step.
  cv::Mat padded(20, 32, CV_8UC1, cv::Scalar(9));
  expected.copyTo(padded(cv::Rect(0, 0, 24, 20)));
  EXPECT_EQ(
      cv::norm(GreyFromRaw("mono8", 24, 20, 32, false, Bytes(padded)), expected, cv::NORM_INF), 0);
}

TEST(CameraImage, RefusesWhatDoesNotFit) {
  const std::string data(100, '\0');
  auto refused = [&](const std::string& enc, std::uint32_t w, std::uint32_t h, std::uint32_t step,
                     const std::string& bytes, const std::string& needle) {
    try {
      GreyFromRaw(enc, w, h, step, false, bytes);
      ADD_FAILURE() << "accepted " << enc << " " << w << "x" << h;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    }
  };
  refused("yuv422", 16, 16, 32, std::string(512, '\0'), "yuv422");
  refused("mono8", 16, 16, 16, data, "step x height");
  refused("mono8", 16, 16, 8, std::string(256, '\0'), "less than a row");
  refused("mono8", 100000, 16, 100000, data, "100000x16");
  refused("mono8", 4, 4, 4, data, "4x4");
  refused("rgb8", 0xFFFFFFFFu, 0xFFFFFFFFu, 0xFFFFFFFFu, data, "must be 16x16");
}

TEST(CameraImage, DecodesCompressedAndPreparesFrames) {
  cv::Mat grey(48, 64, CV_8UC1);
  cv::randu(grey, 0, 255);
  std::vector<uchar> png;
  io::lazy::ImEncode(".png", grey, &png, {});
  const cv::Mat back = GreyFromCompressed("png", std::string(png.begin(), png.end()));
  EXPECT_EQ(cv::norm(back, grey, cv::NORM_INF), 0);
  EXPECT_THROW(GreyFromCompressed("png", "not a png at all"), InputError);
  EXPECT_THROW(GreyFromCompressed("theora", "x"), InputError);

  const cv::Mat turned = PrepareFrame(grey, CameraMount::kRotated180, {});
  EXPECT_EQ(turned.at<uchar>(0, 0), grey.at<uchar>(47, 63));
  const cv::Mat small = PrepareFrame(grey, CameraMount::kUpright, {32, 24});
  EXPECT_EQ(small.size(), cv::Size(32, 24));
  EXPECT_EQ(small.type(), CV_8UC1);
}

}  // namespace
}  // namespace mapless::robot
