#include "mapless/features/features.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <iostream>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

#include "mapless/core/check.h"
#include "mapless/features/klt.h"
#include "mapless/sim/simulation.h"

namespace mapless::features {
namespace {

cv::Mat SimFrame(const char* scenario, const Pose2& pose) {
  const sim::Scenario s = sim::LoadScenario(scenario);
  sim::Simulation sim(s.world, s.camera, {}, 1);
  sim.AddRobot(pose, s.robot);
  return sim.RenderClean(0);
}

TEST(FeatureExtractor, EveryDetectorFindsFeaturesOnASimulatorFrame) {
  const cv::Mat frame = SimFrame("table1_almost_straight", Pose2{1.0, 0.0, 0.0});
  for (const char* name : {"orb", "akaze", "akaze_upright", "sift"}) {
    FeatureOptions o;
    o.type = ParseDetectorType(name);
    const Features f = FeatureExtractor(o).Extract(frame);
    EXPECT_GE(f.keypoints.size(), 100u) << name;
    EXPECT_EQ(static_cast<std::size_t>(f.descriptors.rows), f.keypoints.size()) << name;
    EXPECT_EQ(f.binary, o.type != DetectorType::kSift) << name;
  }
  EXPECT_THROW(ParseDetectorType("surf"), InputError);
}

TEST(MatchFeatures, AFrameMatchedWithItselfGivesIdentityMatches) {
  const cv::Mat frame = SimFrame("table1_almost_straight", Pose2{1.0, 0.0, 0.0});
  const FeatureExtractor extractor(FeatureOptions{});
  const Features f = extractor.Extract(frame);
  MatchOptions m;
  m.mutual = true;
  const auto matches = MatchFeatures(f, f, m);
  ASSERT_GT(matches.size(), 50u);
  int identity = 0;
  for (const auto& match : matches) identity += match.queryIdx == match.trainIdx ? 1 : 0;
  EXPECT_GT(identity, static_cast<int>(0.95 * static_cast<double>(matches.size())));
}

TEST(MatchFeatures, VerticalOffsetBoundRejectsMatches) {
  const cv::Mat frame = SimFrame("table1_almost_straight", Pose2{1.0, 0.0, 0.0});
  cv::Mat moved;
  const cv::Mat shift = (cv::Mat_<double>(2, 3) << 1, 0, 0, 0, 1, 20);
  cv::warpAffine(frame, moved, shift, frame.size());
  const FeatureExtractor extractor(FeatureOptions{});
  MatchOptions loose;
  MatchOptions tight;
  tight.max_dy_px = 5.0;
  const Features a = extractor.Extract(frame);
  const Features b = extractor.Extract(moved);
  EXPECT_GT(MatchFeatures(a, b, loose).size(), 50u);
  EXPECT_LT(MatchFeatures(a, b, tight).size(), MatchFeatures(a, b, loose).size() / 5);
}

// A repeating texture: the query feature has two identical candidates 40 px apart. The ratio test
// rejects the ambiguous match; a displacement prediction keeps only the candidate near it.
TEST(MatchFeatures, GuidedMatchingResolvesARepeatingPattern) {
  cv::Mat d = cv::Mat::zeros(1, 32, CV_8U);
  for (int i = 0; i < 32; ++i) d.at<uchar>(0, i) = static_cast<uchar>(37 * i + 11);
  Features query;
  query.keypoints = {cv::KeyPoint(100.f, 50.f, 31.f)};
  query.descriptors = d.clone();
  Features train;
  train.keypoints = {cv::KeyPoint(95.f, 50.f, 31.f), cv::KeyPoint(135.f, 50.f, 31.f)};
  cv::vconcat(d, d, train.descriptors);
  MatchOptions plain;
  EXPECT_TRUE(MatchFeatures(query, train, plain).empty());
  MatchOptions guided;
  guided.expected_dx_px = -35.0;  // x_query - x_train predicted: the feature at 135
  guided.max_ddx_px = 15.0;
  const auto near_135 = MatchFeatures(query, train, guided);
  ASSERT_EQ(near_135.size(), 1u);
  EXPECT_EQ(near_135[0].trainIdx, 1);
  guided.expected_dx_px = 5.0;  // the feature at 95
  const auto near_95 = MatchFeatures(query, train, guided);
  ASSERT_EQ(near_95.size(), 1u);
  EXPECT_EQ(near_95[0].trainIdx, 0);
  guided.expected_dx_px = 200.0;  // nothing near the prediction
  EXPECT_TRUE(MatchFeatures(query, train, guided).empty());
}

// Frames along two routes matched with frames up to 1 m ahead, ORB and AKAZE, plain and guided,
// with and without the mutual check: every match (indices and distance) equals BFMatcher's
// (MatchFeaturesBruteForce, what MatchFeatures did for every descriptor before).
// The float fast path (no ratio test, no window: the shift estimator's matching) gives
// BFMatcher's nearest neighbours, with and without the mutual check.
TEST(MatchFeatures, FloatNearestMatchesAreOpenCvBruteForceMatches) {
  std::size_t matches_seen = 0;
  FeatureOptions fo;
  fo.type = DetectorType::kAkazeSift;
  const FeatureExtractor extractor(fo);
  for (const char* scenario : {"table1_almost_straight", "office_aliasing"}) {
    const Features a = extractor.Extract(SimFrame(scenario, Pose2{0.5, 0.05, 0.02}));
    const Features b = extractor.Extract(SimFrame(scenario, Pose2{0.9, 0.0, 0.0}));
    ASSERT_FALSE(a.binary);
    for (const bool mutual : {false, true}) {
      MatchOptions m;
      m.ratio = 1.0;
      m.mutual = mutual;
      const auto got = MatchFeatures(a, b, m);
      const auto want = MatchFeaturesBruteForce(a, b, m);
      ASSERT_EQ(got.size(), want.size()) << scenario << " mutual " << mutual;
      for (std::size_t i = 0; i < got.size(); ++i) {
        EXPECT_EQ(got[i].queryIdx, want[i].queryIdx);
        EXPECT_EQ(got[i].trainIdx, want[i].trainIdx);
        EXPECT_NEAR(got[i].distance, want[i].distance, 1e-3 * want[i].distance + 1e-3);
      }
      matches_seen += got.size();
    }
  }
  EXPECT_GT(matches_seen, 4u * 20u);  // the comparisons are not of empty match sets
}

TEST(MatchFeatures, BinaryMatchesAreExactlyOpenCvBruteForceMatches) {
  int compared = 0;
  std::size_t matches_seen = 0;
  for (const char* scenario : {"table1_almost_straight", "office_aliasing"}) {
    for (const char* detector : {"orb", "akaze"}) {
      FeatureOptions fo;
      fo.type = ParseDetectorType(detector);
      const FeatureExtractor extractor(fo);
      for (int k = 0; k < 2; ++k) {
        const double x = 0.5 + 1.5 * k;
        const Features a = extractor.Extract(SimFrame(scenario, Pose2{x, 0.05, 0.02}));
        const Features b =
            extractor.Extract(SimFrame(scenario, Pose2{x + 0.4 + 0.3 * k, 0.0, 0.0}));
        for (int variant = 0; variant < 4; ++variant) {
          MatchOptions m;
          m.ratio = 0.8;
          m.mutual = variant % 2 == 1;
          if (variant >= 2) {
            m.max_dy_px = 30.0;
            m.expected_dx_px = -10.0 * k;
            m.max_ddx_px = 40.0;
          }
          const auto got = MatchFeatures(a, b, m);
          const auto want = MatchFeaturesBruteForce(a, b, m);
          ASSERT_EQ(got.size(), want.size())
              << scenario << " " << detector << " " << k << " " << variant;
          for (std::size_t i = 0; i < got.size(); ++i) {
            EXPECT_EQ(got[i].queryIdx, want[i].queryIdx);
            EXPECT_EQ(got[i].trainIdx, want[i].trainIdx);
            EXPECT_FLOAT_EQ(got[i].distance, want[i].distance);
          }
          matches_seen += got.size();
          ++compared;
        }
      }
    }
  }
  EXPECT_EQ(compared, 32);
  EXPECT_GT(matches_seen, 32u * 20u);  // the comparisons are not of empty match sets
}

// On a known sub-pixel translation: full-resolution tracking (the default) within 0.1 px, half
// resolution within 0.2 px, for 90% of the points tracked.
TEST(TrackKlt, RecoversASubPixelTranslation) {
  const cv::Mat frame = SimFrame("table1_almost_straight", Pose2{1.0, 0.0, 0.0});
  cv::Mat moved;
  const cv::Mat shift = (cv::Mat_<double>(2, 3) << 1, 0, 2.3, 0, 1, -1.1);
  cv::warpAffine(frame, moved, shift, frame.size(), cv::INTER_LINEAR, cv::BORDER_REFLECT);
  std::vector<cv::Point2f> corners;
  cv::goodFeaturesToTrack(frame, corners, 200, 0.01, 8);
  for (const auto& [finest_level, tolerance_px] : {std::pair{0, 0.1f}, std::pair{1, 0.2f}}) {
    KltOptions o;
    o.finest_level = finest_level;
    const KltResult r = TrackKlt(frame, moved, corners, o);
    ASSERT_GT(r.tracked, 150);
    int accurate = 0;
    for (std::size_t i = 0; i < corners.size(); ++i) {
      if (!r.ok[i]) continue;
      const cv::Point2f d = r.points[i] - corners[i];
      if (std::abs(d.x - 2.3f) < tolerance_px && std::abs(d.y + 1.1f) < tolerance_px) ++accurate;
    }
    EXPECT_GT(accurate, static_cast<int>(0.9 * r.tracked)) << "finest_level " << finest_level;
  }
}

TEST(TrackKlt, LosesPointsThatLeaveTheImageOrHitAnotherView) {
  const cv::Mat a = SimFrame("table1_almost_straight", Pose2{1.0, 0.0, 0.0});
  const cv::Mat b =
      SimFrame("table1_almost_straight", Pose2{1.0, 0.0, kPi / 2});  // looking at a wall
  std::vector<cv::Point2f> corners;
  cv::goodFeaturesToTrack(a, corners, 200, 0.01, 8);
  const KltResult r = TrackKlt(a, b, corners, KltOptions{});
  EXPECT_LT(r.tracked, static_cast<int>(corners.size()) / 4);
}

// At finest_level 0, the pyramid API gives exactly what OpenCV's tracker gives on the two images
// (the pyramid with its derivatives is what calcOpticalFlowPyrLK builds inside).
TEST(TrackKlt, FullResolutionIsOpenCvsTrackerBitForBit) {
  const cv::Mat a = SimFrame("table1_almost_straight", Pose2{1.0, 0.0, 0.0});
  const cv::Mat b = SimFrame("table1_almost_straight", Pose2{1.05, 0.01, 0.02});
  std::vector<cv::Point2f> corners;
  cv::goodFeaturesToTrack(a, corners, 200, 0.01, 8);
  KltOptions o;
  o.finest_level = 0;
  const KltResult r = TrackKlt(BuildKltPyramid(a, o), BuildKltPyramid(b, o), corners, o);
  std::vector<cv::Point2f> forward;
  std::vector<uchar> status;
  std::vector<float> err;
  cv::calcOpticalFlowPyrLK(
      a, b, corners, forward, status, err, cv::Size(31, 31), 3,
      cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 30, 0.01));
  ASSERT_GT(r.tracked, 100);
  for (std::size_t i = 0; i < corners.size(); ++i) {
    if (r.ok[i]) {
      EXPECT_EQ(r.points[i], forward[i]) << i;
    }
  }
}

// finest_level 1 (the default) tracks on the half-resolution image with the window halved: close
// to the full resolution, on a real view change of the simulator (forward motion and a turn).
TEST(TrackKlt, HalfResolutionStaysCloseToFullResolution) {
  const cv::Mat a = SimFrame("table1_almost_straight", Pose2{1.0, 0.0, 0.0});
  const cv::Mat b = SimFrame("table1_almost_straight", Pose2{1.05, 0.01, 0.02});
  std::vector<cv::Point2f> corners;
  cv::goodFeaturesToTrack(a, corners, 200, 0.01, 8);
  KltOptions full;
  full.finest_level = 0;
  const KltResult f = TrackKlt(a, b, corners, full);
  KltOptions half;
  EXPECT_EQ(half.finest_level, 1);
  const KltResult h = TrackKlt(a, b, corners, half);
  EXPECT_EQ(half.LevelWindowPx(), 15);
  std::vector<double> differences;
  for (std::size_t i = 0; i < corners.size(); ++i) {
    if (f.ok[i] && h.ok[i]) differences.push_back(cv::norm(f.points[i] - h.points[i]));
  }
  ASSERT_GT(differences.size(), static_cast<std::size_t>(0.9 * f.tracked));
  std::sort(differences.begin(), differences.end());
  const double median = differences[differences.size() / 2];
  const double p90 = differences[differences.size() * 9 / 10];
  std::cout << "half vs full resolution: median " << median << " px, 90th percentile " << p90
            << " px over " << differences.size() << " points\n";
  EXPECT_LT(median, 0.25);
  EXPECT_LT(p90, 1.0);
}

TEST(KltOptions, RefusesAFinestLevelAboveThePyramidOrATooSmallWindow) {
  KltOptions o;
  o.finest_level = 4;
  EXPECT_THROW(o.Validate(), std::exception);
  o.finest_level = 1;
  o.window_px = 9;  // 4 -> 5 px at level 1: allowed
  EXPECT_NO_THROW(o.Validate());
  o.finest_level = 2;  // 2 -> 3 px
  EXPECT_THROW(o.Validate(), std::exception);
}

}  // namespace
}  // namespace mapless::features
