#include "mapless/ground/dominant_plane.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "mapless/flow/flow.h"
#include "mapless/io/image_file.h"

namespace mapless::ground {
namespace {

// A flow field: planar flow of `model` everywhere, except a block (the obstacle) that moves with
// `obstacle_flow`, plus a little noise.
cv::Mat SyntheticFlow(const cv::Mat& model, const cv::Rect& obstacle, cv::Vec2f obstacle_flow) {
  cv::Mat flow = PlanarFlow(model, cv::Size(320, 240));
  flow(obstacle).setTo(cv::Scalar(obstacle_flow[0], obstacle_flow[1]));
  cv::Mat noise(flow.size(), CV_32FC2);
  cv::RNG rng(7);
  rng.fill(noise, cv::RNG::NORMAL, 0.0, 0.1);
  return flow + noise;
}

cv::Mat GroundHomography() {
  // Forward motion over the ground seen by a pitched camera: points spread away from the
  // horizon and move down, faster near the bottom.
  return (cv::Mat_<double>(3, 3) << 1.02, 0.0, -3.2, 0.0, 1.05, -4.0, 0.0, 0.0002, 1.0);
}

TEST(DetectDominantPlane, RecoversAKnownHomographyWithAnObstacle) {
  const cv::Mat h = GroundHomography();
  const cv::Rect obstacle(200, 60, 80, 120);  // 12.5% of the image, as outliers
  const cv::Mat flow = SyntheticFlow(h, obstacle, cv::Vec2f(-4.f, 0.5f));
  DominantPlaneOptions options;
  options.epsilon_px = 0.5;
  const DominantPlane plane = DetectDominantPlane(flow, options);
  ASSERT_TRUE(plane.found);
  const cv::Mat err = PlanarFlow(plane.model, flow.size()) - PlanarFlow(h, flow.size());
  EXPECT_LT(cv::norm(err, cv::NORM_INF), 0.1);
  // The obstacle is off the plane, the rest is on it.
  const cv::Rect inner(obstacle.x + 4, obstacle.y + 4, obstacle.width - 8, obstacle.height - 8);
  EXPECT_EQ(cv::countNonZero(plane.mask(inner)), 0);
  EXPECT_GT(cv::countNonZero(plane.mask(cv::Rect(0, 0, 180, 240))), 0.98 * 180 * 240);
  EXPECT_GT(plane.iterations, 0);
  EXPECT_LT(plane.iterations, 320 * 240 / 2);  // adaptive, far below the paper's fixed count
}

TEST(DetectDominantPlane, NearerFractionCutsWhatMovesMoreThanTheGroundButNotLess) {
  // Two blocks whose flow differs from the ground's by 1.5 px along the planar flow: one moves
  // more (nearer than the ground: something standing on it), one less. Both are inside the
  // circular tolerance 0.5 px + 0.4 |u_hat| (the nearer block: |u_hat| 4.3-5.1 px, 2.2-2.5 px;
  // the farther one more); half of it along the flow (1.1-1.3 px there) cuts the first only.
  const cv::Mat h = GroundHomography();
  cv::Mat flow = PlanarFlow(h, cv::Size(320, 240));
  const cv::Rect nearer(40, 180, 40, 40);
  const cv::Rect farther(240, 180, 40, 40);
  for (const auto& [block, sign] : {std::pair{nearer, 1.0F}, std::pair{farther, -1.0F}}) {
    for (int y = block.y; y < block.br().y; ++y) {
      for (int x = block.x; x < block.br().x; ++x) {
        cv::Vec2f& u = flow.at<cv::Vec2f>(y, x);
        u += 1.5F * sign * u / cv::norm(u);
      }
    }
  }
  DominantPlaneOptions options;
  options.epsilon_px = 0.5;
  options.epsilon_relative = 0.4;
  options.open_px = 0;
  const auto on_plane = [&](const cv::Rect& block, double nearer_fraction) {
    options.nearer_fraction = nearer_fraction;
    const DominantPlane plane = DetectDominantPlane(flow, options);
    EXPECT_TRUE(plane.found);
    return cv::countNonZero(plane.mask(block)) / static_cast<double>(block.area());
  };
  EXPECT_GT(on_plane(nearer, 1.0), 0.99);  // the paper's circle keeps both
  EXPECT_GT(on_plane(farther, 1.0), 0.99);
  EXPECT_LT(on_plane(nearer, 0.5), 0.01);
  EXPECT_GT(on_plane(farther, 0.5), 0.99);
}

TEST(DetectDominantPlane, TheAffineModelRecoversAnAffineFlow) {
  const cv::Mat a = (cv::Mat_<double>(3, 3) << 1.01, 0.02, -2.0, -0.01, 1.03, 1.5, 0.0, 0.0, 1.0);
  const cv::Mat flow = SyntheticFlow(a, cv::Rect(0, 0, 100, 100), cv::Vec2f(5.f, 5.f));
  DominantPlaneOptions options;
  options.model = PlaneModel::kAffine;
  options.epsilon_px = 0.5;
  const DominantPlane plane = DetectDominantPlane(flow, options);
  ASSERT_TRUE(plane.found);
  const cv::Mat err = PlanarFlow(plane.model, flow.size()) - PlanarFlow(a, flow.size());
  EXPECT_LT(cv::norm(err, cv::NORM_INF), 0.1);
  EXPECT_DOUBLE_EQ(plane.model.at<double>(2, 0), 0.0);  // affine: last row 0 0 1
}

TEST(DetectDominantPlane, AWallFillingTheViewIsNoPlane) {
  // 70% of the image (the top, down to near the bottom) moves unlike the ground.
  const cv::Mat flow =
      SyntheticFlow(GroundHomography(), cv::Rect(0, 0, 320, 170), cv::Vec2f(0.3f, 0.2f));
  DominantPlaneOptions options;
  options.epsilon_px = 0.5;
  const DominantPlane plane = DetectDominantPlane(flow, options);
  EXPECT_FALSE(plane.found);
  EXPECT_EQ(cv::countNonZero(plane.mask), 0);
}

TEST(InclusionMeasure, FollowsEq23) {
  cv::Mat a = cv::Mat::zeros(8, 8, CV_8U);
  cv::Mat b = cv::Mat::zeros(4, 4, CV_8U);
  a(cv::Rect(0, 4, 8, 4)).setTo(255);  // bottom half
  b(cv::Rect(0, 2, 4, 2)).setTo(255);  // bottom half at half resolution
  EXPECT_DOUBLE_EQ(InclusionMeasure(a, b), 1.0);
  cv::Mat disjoint = cv::Mat::zeros(4, 4, CV_8U);
  disjoint(cv::Rect(0, 0, 4, 2)).setTo(255);
  EXPECT_DOUBLE_EQ(InclusionMeasure(a, disjoint), 0.0);
  cv::Mat half = cv::Mat::zeros(4, 4, CV_8U);
  half(cv::Rect(0, 1, 4, 2)).setTo(255);
  EXPECT_DOUBLE_EQ(InclusionMeasure(a, half), 0.5);
}

TEST(MaskIoU, CountsInsideTheRoi) {
  cv::Mat a = cv::Mat::zeros(4, 4, CV_8U);
  cv::Mat b = cv::Mat::zeros(4, 4, CV_8U);
  a(cv::Rect(0, 2, 4, 2)).setTo(255);
  b(cv::Rect(0, 3, 4, 1)).setTo(255);
  EXPECT_DOUBLE_EQ(MaskIoU(a, b), 0.5);
  EXPECT_DOUBLE_EQ(MaskIoU(a, b, cv::Rect(0, 3, 4, 1)), 1.0);
}

// Real data: CamVid, a car camera in town with hand-labelled road and pavement (shared data
// folder). The configuration of `mapless ground`: DIS medium, homography, epsilon 0.4 px + 0.4
// |u_hat|, bottom-half ROI, RANSAC on the bottom half of it; IoU over the bottom half, mean over
// all 50 consecutive pairs (measured 0.803; the issue asks for more than 0.8).
TEST(DetectDominantPlane, CamVidGroundIoU) {
  const std::string dir = std::string(MAPLESS_SOURCE_DIR) + "/../shared/data/camvid_seq";
  if (!std::filesystem::exists(dir + "/frames")) GTEST_SKIP() << "shared data not found at " << dir;
  std::vector<std::string> names;
  for (const auto& e : std::filesystem::directory_iterator(dir + "/frames"))
    names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  ASSERT_GE(names.size(), 2u);
  flow::FlowOptions flow_options;
  flow_options.method = flow::FlowMethod::kDisMedium;
  DominantPlaneOptions options;
  options.epsilon_px = 0.4;
  options.epsilon_relative = 0.4;
  options.roi_top_fraction = 0.5;
  options.fit_bottom_fraction = 0.5;
  DominantPlaneOptions paper = options;  // the paper's fixed tolerance, for comparison
  paper.epsilon_px = 1.0;
  paper.epsilon_relative = 0.0;
  double sum = 0.0;
  double sum_paper = 0.0;
  for (std::size_t i = 0; i + 1 < names.size(); ++i) {
    const cv::Mat a = io::ReadImage(dir + "/frames/" + names[i], cv::IMREAD_GRAYSCALE);
    const cv::Mat b = io::ReadImage(dir + "/frames/" + names[i + 1], cv::IMREAD_GRAYSCALE);
    const cv::Mat truth = io::ReadImage(dir + "/ground/" + names[i], cv::IMREAD_GRAYSCALE) > 127;
    const cv::Mat field = flow::ComputeFlow(a, b, flow_options);
    const cv::Rect bottom(0, a.rows / 2, a.cols, a.rows - a.rows / 2);
    sum += MaskIoU(DetectDominantPlane(field, options).mask, truth, bottom);
    sum_paper += MaskIoU(DetectDominantPlane(field, paper).mask, truth, bottom);
  }
  const double n = static_cast<double>(names.size() - 1);
  std::printf("CamVid ground IoU (bottom half, %d pairs): %.3f; fixed epsilon 1 px: %.3f\n",
              static_cast<int>(n), sum / n, sum_paper / n);
  EXPECT_GT(sum / n, 0.8);
  EXPECT_GT(sum / n, sum_paper / n + 0.1);
}

}  // namespace
}  // namespace mapless::ground
