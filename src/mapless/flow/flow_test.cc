#include "mapless/flow/flow.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

#include "mapless/core/check.h"
#include "mapless/core/testing.h"
#include "mapless/io/atomic_file.h"
#include "mapless/io/flo.h"
#include "mapless/io/image_file.h"

namespace mapless::flow {
namespace {

// A smooth random texture (blurred noise), so every method has gradients everywhere.
cv::Mat Texture(int width, int height, int seed) {
  cv::Mat noise(height, width, CV_8U);
  cv::RNG rng(static_cast<std::uint64_t>(seed));
  rng.fill(noise, cv::RNG::UNIFORM, 0, 256);
  cv::Mat smooth;
  cv::GaussianBlur(noise, smooth, cv::Size(0, 0), 2.0);
  cv::normalize(smooth, smooth, 0, 255, cv::NORM_MINMAX);
  return smooth;
}

cv::Mat Translate(const cv::Mat& image, double dx, double dy) {
  cv::Mat out;
  const cv::Mat m = (cv::Mat_<double>(2, 3) << 1, 0, dx, 0, 1, dy);
  cv::warpAffine(image, out, m, image.size(), cv::INTER_CUBIC, cv::BORDER_REFLECT101);
  return out;
}

// Mean flow error over the interior (away from borders that moved out of view).
double InteriorError(const cv::Mat& flow, double dx, double dy) {
  const cv::Rect inner(20, 20, flow.cols - 40, flow.rows - 40);
  double sum = 0.0;
  for (int y = inner.y; y < inner.y + inner.height; ++y) {
    for (int x = inner.x; x < inner.x + inner.width; ++x) {
      const cv::Vec2f f = flow.at<cv::Vec2f>(y, x);
      sum += std::hypot(f[0] - dx, f[1] - dy);
    }
  }
  return sum / inner.area();
}

class EveryMethod : public ::testing::TestWithParam<const char*> {};

TEST_P(EveryMethod, RecoversAKnownTranslation) {
  const cv::Mat a = Texture(320, 240, 3);
  const cv::Mat b = Translate(a, 3.4, -1.7);
  FlowOptions options;
  options.method = ParseFlowMethod(GetParam());
  const cv::Mat flow = ComputeFlow(a, b, options);
  ASSERT_EQ(flow.type(), CV_32FC2);
  ASSERT_EQ(flow.size(), a.size());
  EXPECT_LT(InteriorError(flow, 3.4, -1.7), 0.3) << GetParam();
}

INSTANTIATE_TEST_SUITE_P(Flow, EveryMethod,
                         ::testing::Values("dis", "dis_medium", "farneback", "lk"));

// Issue 44: DIS's finest level chosen by width (the navigator's 160 px): at 320x240 DIS medium's
// own level, bit for bit; at 640x480 one level coarser (OpenCV's finest scale 2), still right.
TEST(ComputeFlow, DisFlowWidthPicksTheFinestLevel) {
  FlowOptions medium;
  medium.method = FlowMethod::kDisMedium;
  FlowOptions capped = medium;
  capped.dis_max_flow_width_px = 160;
  const cv::Mat a = Texture(320, 240, 5);
  const cv::Mat b = Translate(a, 2.2, 1.1);
  EXPECT_EQ(cv::norm(ComputeFlow(a, b, medium), ComputeFlow(a, b, capped), cv::NORM_INF), 0.0);

  const cv::Mat a2 = Texture(640, 480, 5);
  const cv::Mat b2 = Translate(a2, 4.4, 2.2);
  cv::Mat expected;
  const auto dis = cv::DISOpticalFlow::create(cv::DISOpticalFlow::PRESET_MEDIUM);
  dis->setFinestScale(2);
  dis->calc(a2, b2, expected);
  const cv::Mat flow = ComputeFlow(a2, b2, capped);
  EXPECT_EQ(cv::norm(flow, expected, cv::NORM_INF), 0.0);
  EXPECT_GT(cv::norm(flow, ComputeFlow(a2, b2, medium), cv::NORM_INF), 0.0);
  EXPECT_LT(InteriorError(flow, 4.4, 2.2), 0.3);
  capped.dis_max_flow_width_px = -1;
  EXPECT_THROW(ComputeFlow(a, b, capped), std::exception);
}

TEST(DenseLucasKanade, RecoversALargeMotionThroughThePyramid) {
  const cv::Mat a = Texture(320, 240, 5);
  const cv::Mat b = Translate(a, -12.0, 6.0);  // far beyond a 5x5 window at level 0
  const cv::Mat flow = DenseLucasKanade(a, b, DenseLkOptions{});
  EXPECT_LT(InteriorError(flow, -12.0, 6.0), 0.3);
  DenseLkOptions one_level;
  one_level.levels = 1;
  EXPECT_GT(InteriorError(DenseLucasKanade(a, b, one_level), -12.0, 6.0), 3.0);
}

TEST(DenseLucasKanade, ReturnsEachLayersFlowInItsOwnPixels) {
  const cv::Mat a = Texture(320, 240, 9);
  const cv::Mat b = Translate(a, 8.0, 0.0);
  std::vector<cv::Mat> layers;
  DenseLucasKanade(a, b, DenseLkOptions{}, &layers);
  ASSERT_EQ(layers.size(), 5u);
  EXPECT_EQ(layers[0].size(), cv::Size(320, 240));
  EXPECT_EQ(layers[1].size(), cv::Size(160, 120));
  const cv::Vec2f centre = layers[1].at<cv::Vec2f>(60, 80);
  EXPECT_NEAR(centre[0], 4.0, 0.5);  // 8 px at full resolution is 4 px at layer 1
}

TEST(BuildPyramid, UsesThePapersKernelAndHalvesEachLevel) {
  cv::Mat impulse = cv::Mat::zeros(16, 16, CV_8U);
  impulse.at<uchar>(8, 8) = 160;
  const std::vector<cv::Mat> p = BuildPyramid(impulse, 3);
  ASSERT_EQ(p.size(), 3u);
  EXPECT_EQ(p[1].size(), cv::Size(8, 8));
  EXPECT_EQ(p[2].size(), cv::Size(4, 4));
  // Level 1 samples the smoothed image at even pixels: (8, 8) keeps 1/4 of the impulse.
  EXPECT_FLOAT_EQ(p[1].at<float>(4, 4), 40.f);
  EXPECT_FLOAT_EQ(p[1].at<float>(4, 5), 0.f);  // (8, 10) is two pixels away: outside the kernel
}

TEST(EndPointError, SkipsUnknownAndInvalidPixels) {
  cv::Mat flow(2, 2, CV_32FC2, cv::Vec2f(1.f, 0.f));
  cv::Mat truth(2, 2, CV_32FC2, cv::Vec2f(0.f, 0.f));
  truth.at<cv::Vec2f>(0, 0) = cv::Vec2f(1e10f, 1e10f);  // unknown
  cv::Mat valid(2, 2, CV_8U, cv::Scalar(255));
  valid.at<uchar>(1, 1) = 0;
  const FlowError e = EndPointError(flow, truth, valid);
  EXPECT_EQ(e.count, 2);
  EXPECT_DOUBLE_EQ(e.mean_epe_px, 1.0);
}

TEST(FloFile, RoundTripsAndRejectsBadFiles) {
  const std::string dir = ::testing::TempDir() + "/flo_test";
  std::filesystem::create_directories(dir);
  cv::Mat flow(3, 4, CV_32FC2);
  cv::randu(flow, -5.f, 5.f);
  io::WriteFlo(dir + "/a.flo", flow);
  const cv::Mat back = io::ReadFlo(dir + "/a.flo");
  ASSERT_EQ(back.size(), flow.size());
  EXPECT_EQ(cv::norm(back, flow, cv::NORM_INF), 0.0);
  // Truncated: one error naming the file.
  const std::string bytes = io::ReadFile(dir + "/a.flo", 1 << 20);
  std::ofstream(dir + "/short.flo", std::ios::binary) << bytes.substr(0, bytes.size() - 5);
  EXPECT_THAT(mapless::testing::InputErrorOf([&] { io::ReadFlo(dir + "/short.flo"); }),
              ::testing::HasSubstr("short.flo: truncated"));
  std::ofstream(dir + "/junk.flo", std::ios::binary) << "this is not a flow file";
  EXPECT_THAT(mapless::testing::InputErrorOf([&] { io::ReadFlo(dir + "/junk.flo"); }),
              ::testing::HasSubstr("junk.flo: not a .flo file"));
  EXPECT_THAT(mapless::testing::InputErrorOf([&] { io::ReadFlo(dir + "/missing.flo"); }),
              ::testing::HasSubstr("missing.flo"));
}

// Real data: the Middlebury RubberWhale pair (from the shared data folder when present).
TEST(DenseLucasKanade, RubberWhaleEndPointError) {
  const std::string dir = std::string(MAPLESS_SOURCE_DIR) + "/../shared/data/flow";
  if (!std::filesystem::exists(dir + "/rubberwhale_gt.flo"))
    GTEST_SKIP() << "shared data not found at " << dir;
  const cv::Mat a = io::ReadImage(dir + "/rubberwhale1.png", cv::IMREAD_GRAYSCALE);
  const cv::Mat b = io::ReadImage(dir + "/rubberwhale2.png", cv::IMREAD_GRAYSCALE);
  const cv::Mat truth = io::ReadFlo(dir + "/rubberwhale_gt.flo");
  FlowOptions dis;
  const double dis_epe = EndPointError(ComputeFlow(a, b, dis), truth).mean_epe_px;
  FlowOptions lk;
  lk.method = FlowMethod::kDenseLk;
  const double lk_epe = EndPointError(ComputeFlow(a, b, lk), truth).mean_epe_px;
  // OpenCV's sparse PyrLK asked for every pixel, same 5x5 window and levels 0-4.
  std::vector<cv::Point2f> every, next;
  for (int y = 0; y < a.rows; ++y)
    for (int x = 0; x < a.cols; ++x) every.emplace_back(x, y);
  std::vector<uchar> status;
  std::vector<float> err;
  cv::calcOpticalFlowPyrLK(a, b, every, next, status, err, cv::Size(5, 5), 4);
  cv::Mat pyrlk(a.size(), CV_32FC2);
  for (std::size_t i = 0; i < every.size(); ++i) {
    pyrlk.at<cv::Vec2f>(every[i]) = status[i] ? cv::Vec2f(next[i] - every[i]) : cv::Vec2f(0, 0);
  }
  const double pyrlk_epe = EndPointError(pyrlk, truth).mean_epe_px;
  std::printf("RubberWhale EPE: DIS fast %.3f, dense LK %.3f, per-pixel PyrLK %.3f px\n", dis_epe,
              lk_epe, pyrlk_epe);
  EXPECT_LT(dis_epe, 0.6);       // stock DIS fast: about 0.45 px
  EXPECT_LT(lk_epe, pyrlk_epe);  // no worse than per-pixel PyrLK (5.1 px in the issue)
}

}  // namespace
}  // namespace mapless::flow
