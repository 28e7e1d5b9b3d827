#include "mapless/features/orb.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <opencv2/features2d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <utility>

#include "mapless/io/image_file.h"
#include "mapless/sim/simulation.h"

namespace mapless::features {
namespace {

cv::Mat Grey(const cv::Mat& image) {
  cv::Mat grey = image;
  if (image.channels() == 3) cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  return grey;
}

// Grey frames ahead of a scenario's teach start, `spacing_m` apart, turned a little to and fro.
std::vector<cv::Mat> SimFrames(const char* scenario, int count, double spacing_m) {
  const sim::Scenario s = sim::LoadScenario(scenario);
  sim::Simulation sim(s.world, s.camera, {}, 1);
  sim.AddRobot(s.teach_start, s.robot);
  std::vector<cv::Mat> frames;
  for (int i = 0; i < count; ++i) {
    Pose2 p = s.teach_start;
    p.x_m += spacing_m * i * std::cos(p.theta_rad);
    p.y_m += spacing_m * i * std::sin(p.theta_rad);
    p.theta_rad += 0.05 * (i % 3 - 1);
    sim.PlaceRobot(0, p);
    frames.push_back(Grey(sim.RenderClean(0)));
  }
  return frames;
}

// The same Harris response as cv::ORB's. Bit for bit where OpenCV's build rounds as mapless's
// code does (x86-64); OpenCV's arm64 build contracts its `a*b - c*c - k*(a+b)^2` into fused
// multiply-adds and mapless does not (-ffp-contract=off: x86-64's response on arm64 too,
// docs/arm64.md), so there the two agree within 10 ppm, or 1e-9 where the three terms nearly
// cancel (a few units in the last place of terms up to about 1e-2).
bool SameResponse(float ours, float theirs) {
#if defined(__aarch64__)
  return std::abs(ours - theirs) <= std::max(1e-5f * std::abs(theirs), 1e-9f);
#else
  return ours == theirs;
#endif
}

// The same angle as cv::ORB's (cv::fastAtan2). Bit for bit on x86-64; OpenCV's arm64 build fuses
// the polynomial's multiply-adds (FastAtan2Degrees), so there within a few units in the last
// place (2e-4 degrees, around the circle).
bool SameAngle(float ours, float theirs) {
#if defined(__aarch64__)
  const float d = std::abs(ours - theirs);
  return std::min(d, 360.f - d) <= 2e-4f;
#else
  return ours == theirs;
#endif
}

// The same keypoints (every field; the response as SameResponse, the angle as SameAngle) and
// descriptors, in the same order, as cv::ORB; returns how many. (On arm64 a descriptor is
// compared where the two angles are equal: a different angle rotates the tests.)
std::size_t ExpectSameAsOpenCv(const cv::Mat& grey, int max_features, int threshold,
                               const std::string& what) {
  EXPECT_EQ(OrbTestPairs().size(), 256u) << "without the test pairs OrbDetector is cv::ORB";
  std::vector<cv::KeyPoint> ours;
  cv::Mat ours_d;
  OrbDetector(max_features, threshold).DetectAndCompute(grey, &ours, &ours_d);
  std::vector<cv::KeyPoint> theirs;
  cv::Mat theirs_d;
  cv::ORB::create(max_features, 1.2f, 8, 31, 0, 2, cv::ORB::HARRIS_SCORE, 31, threshold)
      ->detectAndCompute(grey, cv::noArray(), theirs, theirs_d);
  EXPECT_EQ(ours.size(), theirs.size()) << what;
  if (ours.size() != theirs.size()) return 0;
  for (std::size_t i = 0; i < ours.size(); ++i) {
    const cv::KeyPoint& a = ours[i];
    const cv::KeyPoint& b = theirs[i];
    EXPECT_TRUE(a.pt == b.pt && a.size == b.size && SameAngle(a.angle, b.angle) &&
                SameResponse(a.response, b.response) && a.octave == b.octave &&
                a.class_id == b.class_id)
        << what << ": keypoint " << i << " (" << a.pt << " " << a.angle << " " << a.response
        << " level " << a.octave << ") vs (" << b.pt << " " << b.angle << " " << b.response
        << " level " << b.octave << ")";
    if (!(a.pt == b.pt && SameAngle(a.angle, b.angle))) return 0;
  }
  EXPECT_EQ(ours_d.size(), theirs_d.size()) << what;
  EXPECT_EQ(ours_d.type(), theirs_d.type()) << what;
  if (ours_d.size() != theirs_d.size() || ours_d.type() != theirs_d.type()) return 0;
  for (int r = 0; r < ours_d.rows; ++r) {
    if (ours[static_cast<std::size_t>(r)].angle != theirs[static_cast<std::size_t>(r)].angle)
      continue;  // (arm64 only: SameAngle)
    EXPECT_EQ(std::memcmp(ours_d.ptr(r), theirs_d.ptr(r), static_cast<std::size_t>(ours_d.cols)), 0)
        << what << ": descriptor " << r;
  }
  return ours.size();
}

// cv::fastAtan2 of the moments a patch can have (and the axes, the diagonals, zero), bit for bit
// on x86-64; within SameAngle on arm64.
TEST(FastAtan2Degrees, IsOpenCvsFastAtan2) {
  std::vector<std::pair<float, float>> cases = {{0.f, 0.f},  {0.f, 1.f}, {1.f, 0.f},   {0.f, -1.f},
                                                {-1.f, 0.f}, {1.f, 1.f}, {-1.f, -1.f}, {3.f, -3.f}};
  cv::RNG rng(11);
  for (int i = 0; i < 200000; ++i) {
    const int range = i % 2 ? 4000 : 6000000;  // |m01|, |m10| up to 31 * 255 * 751
    cases.emplace_back(static_cast<float>(rng.uniform(-range, range + 1)),
                       static_cast<float>(rng.uniform(-range, range + 1)));
  }
  int different = 0;
  for (const auto& [y, x] : cases) {
    const float ours = FastAtan2Degrees(y, x);
    const float theirs = cv::fastAtan2(y, x);
    EXPECT_TRUE(SameAngle(ours, theirs)) << y << ", " << x << ": " << ours << " vs " << theirs;
    EXPECT_TRUE(ours >= 0.f && ours <= 360.f) << y << ", " << x << ": " << ours;
    different += ours != theirs;
  }
  std::printf("FastAtan2Degrees: %d of %zu angles differ from cv::fastAtan2's\n", different,
              cases.size());
}

TEST(OrbTestPairs, AreReadOffOpenCv) {
  const std::vector<OrbTestPair>& pairs = OrbTestPairs();
  ASSERT_EQ(pairs.size(), 256u);
  for (const OrbTestPair& p : pairs) {
    EXPECT_LE(std::abs(p.first.x), 13);
    EXPECT_LE(std::abs(p.first.y), 13);
    EXPECT_LE(std::abs(p.second.x), 13);
    EXPECT_LE(std::abs(p.second.y), 13);
    EXPECT_NE(p.first, p.second);
  }
}

TEST(OrbDetector, GivesOpenCvsOrbOnSimulatorFrames) {
  for (const char* scenario : {"table1_almost_straight", "corridor_25m", "outdoor_70m",
                               "narrow_room_sharp_turn", "office_aliasing"}) {
    const std::vector<cv::Mat> frames = SimFrames(scenario, 6, 0.7);
    for (std::size_t i = 0; i < frames.size(); ++i) {
      for (const int threshold : {10, 20}) {
        const std::string what = std::string(scenario) + " frame " + std::to_string(i) +
                                 " threshold " + std::to_string(threshold);
        EXPECT_GE(ExpectSameAsOpenCv(frames[i], 500, threshold, what), 100u) << what;
      }
    }
  }
}

TEST(OrbDetector, GivesOpenCvsOrbOnCameraImagesAndOtherSizes) {
  const std::string dir = std::string(MAPLESS_SOURCE_DIR) + "/tests/data/stromovka/";
  for (const char* name : {"0101.png", "0103.png", "0601.png", "1203.png"}) {
    const cv::Mat image = io::ReadImage(dir + name, cv::IMREAD_GRAYSCALE);
    ASSERT_FALSE(image.empty()) << dir + name;
    ExpectSameAsOpenCv(image, 500, 10, name);
    ExpectSameAsOpenCv(image, 1000, 20, std::string(name) + " 1000 features");
    cv::Mat large;
    cv::resize(image, large, cv::Size(641, 481));
    ExpectSameAsOpenCv(large, 500, 10, std::string(name) + " at 641x481");
    cv::Mat small;
    cv::resize(image, small, cv::Size(90, 70));
    ExpectSameAsOpenCv(small, 500, 10, std::string(name) + " at 90x70");
  }
  cv::Mat colour;
  cv::cvtColor(io::ReadImage(dir + "0101.png", cv::IMREAD_GRAYSCALE), colour, cv::COLOR_GRAY2BGR);
  ExpectSameAsOpenCv(colour, 500, 10, "a colour image (cv::ORB's own path)");
  cv::Mat noise(240, 320, CV_8U);
  cv::RNG rng(7);
  rng.fill(noise, cv::RNG::UNIFORM, 0, 256);
  ExpectSameAsOpenCv(noise, 500, 10, "noise");
  ExpectSameAsOpenCv(cv::Mat(240, 320, CV_8U, cv::Scalar(128)), 500, 10, "flat");
  ExpectSameAsOpenCv(cv::Mat(40, 50, CV_8U, cv::Scalar(0)), 500, 10, "too small for any keypoint");
  // Very few features: the geometric split gives none to most levels, the one to the last.
  const cv::Mat stromovka = io::ReadImage(dir + "0101.png", cv::IMREAD_GRAYSCALE);
  ExpectSameAsOpenCv(stromovka, 1, 10, "one feature");
  ExpectSameAsOpenCv(stromovka, 12, 10, "12 features");
}

}  // namespace
}  // namespace mapless::features
