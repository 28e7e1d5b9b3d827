#include "mapless/io/frame_source.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "mapless/core/check.h"
#include "mapless/core/testing.h"

namespace mapless::io {
namespace {

std::string FreshDir(const std::string& name) {
  const std::string dir = ::testing::TempDir() + "mapless_frames_" + name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

cv::Mat Pattern(int k, int w = 64, int h = 48) {
  cv::Mat img(h, w, CV_8UC3, cv::Scalar(20, 20, 20));
  cv::rectangle(img, cv::Rect(4 * k, 10, 12, 12), cv::Scalar(255, 255, 255), cv::FILLED);
  return img;
}

TEST(FrameSource, FolderFramesComeInFileNameOrderAsGreyWithTimestamps) {
  const std::string dir = FreshDir("folder");
  for (int k : {2, 0, 1}) cv::imwrite(dir + "/frame_" + std::to_string(k) + ".png", Pattern(k));
  {  // not an image extension: ignored
    std::FILE* f = std::fopen((dir + "/notes.txt").c_str(), "w");
    std::fputs("calibration notes", f);
    std::fclose(f);
  }
  auto source = OpenFrameSource(dir, 5.0);
  Frame f;
  std::vector<std::string> names;
  while (source->Next(&f)) {
    EXPECT_EQ(f.image.type(), CV_8UC1);
    EXPECT_EQ(f.t_ns, FromSeconds(0.2 * static_cast<double>(names.size())));
    names.push_back(f.name);
  }
  EXPECT_EQ(names, (std::vector<std::string>{"frame_0.png", "frame_1.png", "frame_2.png"}));
}

TEST(FrameSource, FolderWithAnImageOfAnotherSizeNamesIt) {
  const std::string dir = FreshDir("sizes");
  cv::imwrite(dir + "/a.png", Pattern(0));
  cv::imwrite(dir + "/b.png", Pattern(0, 32, 32));
  auto source = OpenFrameSource(dir);
  Frame f;
  ASSERT_TRUE(source->Next(&f));
  EXPECT_NE(testing::InputErrorOf([&] { source->Next(&f); }).find("b.png: image is 32x32"),
            std::string::npos);
}

TEST(FrameSource, VideoFileFramesAreReadInOrder) {
  const std::string dir = FreshDir("video");
  const std::string path = dir + "/clip.avi";
  cv::VideoWriter writer(path, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 10.0, cv::Size(64, 48));
  ASSERT_TRUE(writer.isOpened());
  for (int k = 0; k < 8; ++k) writer.write(Pattern(k));
  writer.release();
  auto source = OpenFrameSource(path);
  Frame f;
  int n = 0;
  while (source->Next(&f)) {
    EXPECT_EQ(f.image.type(), CV_8UC1);
    EXPECT_EQ(f.image.cols, 64);
    // The white square moves right by 4 px per frame.
    EXPECT_GT(f.image.at<std::uint8_t>(16, 4 * n + 6), 150) << n;
    ++n;
  }
  EXPECT_EQ(n, 8);
}

TEST(FrameSource, MissingOrEmptySourcesGiveOneClearError) {
  EXPECT_NE(
      testing::InputErrorOf([] { OpenFrameSource("/nonexistent/video.mp4"); }).find("no such file"),
      std::string::npos);
  const std::string empty = FreshDir("empty");
  EXPECT_NE(testing::InputErrorOf([&] { OpenFrameSource(empty); }).find("no image files"),
            std::string::npos);
  const std::string junk = FreshDir("junk") + "/junk.mp4";
  {
    std::FILE* f = std::fopen(junk.c_str(), "w");
    std::fputs("not a video", f);
    std::fclose(f);
  }
  EXPECT_NE(testing::InputErrorOf([&] { OpenFrameSource(junk); }).find("cannot open video"),
            std::string::npos);
  EXPECT_NE(testing::InputErrorOf([] { OpenFrameSource("camera:x"); }).find("camera:N"),
            std::string::npos);
}

}  // namespace
}  // namespace mapless::io
