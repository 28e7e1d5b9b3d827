#include "mapless/io/image_file.h"

#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "mapless/core/check.h"
#include "mapless/core/testing.h"
#include "mapless/io/limits.h"

namespace mapless::io {
namespace {

std::string Encode(const std::string& ext, const cv::Mat& image) {
  std::vector<uchar> buffer;
  EXPECT_TRUE(cv::imencode(ext, image, buffer));
  return std::string(buffer.begin(), buffer.end());
}

cv::Mat TestImage(int width, int height) {
  cv::Mat m(height, width, CV_8UC1);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) m.at<uchar>(y, x) = static_cast<uchar>((x * 7 + y * 13) % 256);
  return m;
}

TEST(ImageHeader, ReadsTheSizeOfEveryFormatMaplessReads) {
  const cv::Mat image = TestImage(37, 21);
  for (const std::string ext : {".png", ".jpg", ".bmp", ".pgm", ".tif"}) {
    SCOPED_TRACE(ext);
    const auto header = ReadImageHeader(Encode(ext, image));
    ASSERT_TRUE(header.has_value());
    EXPECT_EQ(header->width, 37);
    EXPECT_EQ(header->height, 21);
    const cv::Mat decoded = DecodeImage(Encode(ext, image), "x" + ext, cv::IMREAD_GRAYSCALE);
    EXPECT_EQ(decoded.size(), image.size());
  }
  EXPECT_FALSE(ReadImageHeader("plain text").has_value());
  EXPECT_FALSE(ReadImageHeader("").has_value());
}

TEST(ImageHeader, AHugeDeclaredSizeIsRefusedBeforeDecoding) {
  // A valid PNG whose header is rewritten to declare 30000 x 30000 pixels.
  std::string png = Encode(".png", TestImage(20, 20));
  const std::string big("\x00\x00\x75\x30\x00\x00\x75\x30", 8);
  png.replace(16, 8, big);
  const std::string error = testing::InputErrorOf([&] { DecodeImage(png, "big.png", 0); });
  EXPECT_NE(error.find("big.png (PNG): the header declares 30000x30000 pixels"), std::string::npos)
      << error;
}

TEST(ImageHeader, SmallCutAndForeignImagesAreRefusedByName) {
  const std::string png = Encode(".png", TestImage(8, 8));
  EXPECT_NE(testing::InputErrorOf([&] {
              DecodeImage(png, "s.png", 0, kMinImageSide);
            }).find("s.png (PNG): image is 8x8; at least 16x16"),
            std::string::npos);
  const std::string whole = Encode(".png", TestImage(40, 30));
  EXPECT_NE(testing::InputErrorOf([&] {
              DecodeImage(whole.substr(0, whole.size() - 20), "c.png", 0);
            }).find("c.png (PNG): corrupt image"),
            std::string::npos);
  const std::string jpeg = Encode(".jpg", TestImage(40, 30));
  EXPECT_NE(testing::InputErrorOf([&] {
              DecodeImage(jpeg.substr(0, jpeg.size() / 2), "c.jpg", 0);
            }).find("c.jpg (JPEG): corrupt image"),
            std::string::npos);
  EXPECT_NE(testing::InputErrorOf([&] {
              DecodeImage("GIF89a......", "a.gif", 0);
            }).find("a.gif: not an image mapless reads"),
            std::string::npos);
}

TEST(FrameSize, LimitsAreNamed) {
  EXPECT_NO_THROW(CheckFrameSize(320, 240, "f"));
  EXPECT_NE(testing::InputErrorOf([] { CheckFrameSize(15, 240, "f"); }).find("at least 16x16"),
            std::string::npos);
  EXPECT_NE(testing::InputErrorOf([] { CheckFrameSize(8000, 8000, "f"); }).find("40 megapixels"),
            std::string::npos);
}

}  // namespace
}  // namespace mapless::io
