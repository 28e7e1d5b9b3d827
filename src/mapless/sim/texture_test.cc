#include "mapless/sim/texture.h"

#include <gtest/gtest.h>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "mapless/core/check.h"
#include "mapless/io/atomic_file.h"

namespace mapless::sim {
namespace {

TEST(Texture, SameSpecGivesSameImageAndOtherSeedDiffers) {
  for (const char* type : {"noise", "bricks", "tiles", "blobs", "poster", "plain"}) {
    TextureSpec a;
    a.type = ParseTextureType(type);
    a.seed = 4;
    TextureSpec b = a;
    b.seed = 5;
    const cv::Mat ia = GenerateTextureImage(a);
    EXPECT_EQ(cv::norm(ia, GenerateTextureImage(a), cv::NORM_INF), 0.0) << type;
    EXPECT_GT(cv::norm(ia, GenerateTextureImage(b), cv::NORM_L1), 0.0) << type;
  }
}

TEST(Texture, MipPyramidHalvesDownToOnePixel) {
  TextureSpec spec;
  spec.size_px = 256;
  const auto tex = GenerateTexture(spec);
  ASSERT_EQ(tex->levels.size(), 9u);
  for (std::size_t i = 0; i < tex->levels.size(); ++i) {
    EXPECT_EQ(tex->levels[i].cols, 256 >> i);
    EXPECT_EQ(tex->levels[i].rows, 256 >> i);
  }
}

TEST(Texture, LowContrastVariantIsMuchFlatterThanNormal) {
  TextureSpec normal;
  normal.type = TextureType::kBlobs;
  TextureSpec low = normal;
  low.contrast = 0.15;
  cv::Scalar m1, s1, m2, s2;
  cv::meanStdDev(GenerateTextureImage(normal), m1, s1);
  cv::meanStdDev(GenerateTextureImage(low), m2, s2);
  EXPECT_LT(s2[0], 0.25 * s1[0]);
}

TEST(Texture, ImageFileTextureIsLoadedAsGreyAndResized) {
  const std::string path = ::testing::TempDir() + "mapless_texture.png";
  cv::Mat colour(40, 60, CV_8UC3, cv::Scalar(0, 0, 0));
  cv::rectangle(colour, cv::Rect(0, 0, 30, 40), cv::Scalar(255, 255, 255), cv::FILLED);
  io::WriteImageAtomic(path, colour);
  TextureSpec spec;
  spec.type = TextureType::kImage;
  spec.file = path;
  spec.size_px = 64;
  const cv::Mat img = GenerateTextureImage(spec);
  ASSERT_EQ(img.type(), CV_8UC1);
  ASSERT_EQ(img.size(), cv::Size(64, 64));
  EXPECT_GT(img.at<std::uint8_t>(32, 5), 200);  // left half white
  EXPECT_LT(img.at<std::uint8_t>(32, 58), 50);  // right half black
  spec.file = "/nonexistent/texture.png";
  try {
    GenerateTextureImage(spec);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/texture.png"), std::string::npos);
  }
}

TEST(Texture, InvalidSpecNamesTheField) {
  TextureSpec spec;
  spec.size_px = 300;
  try {
    spec.Validate();
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("TextureSpec.size_px = 300"), std::string::npos);
  }
  EXPECT_THROW(ParseTextureType("marble"), InputError);
}

}  // namespace
}  // namespace mapless::sim
