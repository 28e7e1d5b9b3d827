#include "mapless/io/lazy_libraries.h"

#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>
#include <stdexcept>

#include "mapless/io/lazy_ffmpeg.h"

namespace mapless::io::lazy {
namespace {

TEST(LazyLibraries, ImagesRoundTripThroughTheLoadedCodecs) {
  cv::Mat image(24, 32, CV_8UC1);
  cv::randu(image, 0, 256);
  std::vector<uchar> png;
  ASSERT_TRUE(ImEncode(".png", image, &png, {}));
  // What cv::imencode, linked, writes.
  std::vector<uchar> linked;
  ASSERT_TRUE(cv::imencode(".png", image, linked));
  EXPECT_EQ(png, linked);
  const cv::Mat back = ImDecode(cv::Mat(png), cv::IMREAD_GRAYSCALE);
  ASSERT_EQ(back.size(), image.size());
  EXPECT_EQ(cv::norm(back, image, cv::NORM_INF), 0.0);
  std::vector<uchar> jpeg;
  ASSERT_TRUE(ImEncode(".jpg", image, &jpeg, {cv::IMWRITE_JPEG_QUALITY, 80}));
  ASSERT_TRUE(cv::imencode(".jpg", image, linked, {cv::IMWRITE_JPEG_QUALITY, 80}));
  EXPECT_EQ(jpeg, linked);
}

TEST(LazyLibraries, FfmpegsFunctionsAreAllFound) {
  const Ffmpeg& ff = LoadFfmpeg();
  EXPECT_NE(ff.avformat_open_input, nullptr);
  EXPECT_NE(ff.sws_scale, nullptr);
  EXPECT_NE(ff.av_log_set_callback, nullptr);
}

TEST(LazyLibraries, AMissingLibraryOrFunctionIsOneErrorNamingIt) {
  try {
    OpenLibrary("/nonexistent/libnothing.so.1", "libnothing.so.1", "to test the loader");
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("cannot load libnothing.so.1 (needed to test the loader)"),
              std::string::npos)
        << e.what();
  }
  void* libc = OpenLibrary("", "libc.so.6", "to test the loader");
  EXPECT_NE(Symbol(libc, "malloc", "libc.so.6"), nullptr);
  try {
    Symbol(libc, "no_such_function_here", "libc.so.6");
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("libc.so.6 has no function no_such_function_here"),
              std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace mapless::io::lazy
