#include "mapless/features/shift.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "mapless/io/image_file.h"
#include "mapless/sim/simulation.h"

namespace mapless::features {
namespace {

TEST(VoteShift, PicksTheModeDespiteOutliers) {
  std::vector<double> dx = {30.2, 31.0, 29.5, 30.8, 30.1, 29.9, -80, 55, 140, 2, -3};
  const ShiftEstimate e = VoteShift(dx, 10.0, 5);
  EXPECT_TRUE(e.ok);
  EXPECT_NEAR(e.dx_px, 30.1, 0.6);
  EXPECT_EQ(e.inliers, 6);
  EXPECT_EQ(e.matches, 11);
}

TEST(VoteShift, TooFewVotesIsNotOk) {
  EXPECT_FALSE(VoteShift({1.0, 2.0}, 10.0, 5).ok);
  EXPECT_FALSE(VoteShift({}, 10.0, 5).ok);
}

TEST(VoteShift2D, AFalseMatchThatAgreesOnDxAloneLosesTheVote) {
  // Eight true matches at (30, 6): the camera came back a little higher. Nine false ones agree on
  // dx = -50 but scatter in dy: a vote on dx alone picks them, the (dx, dy) vote does not.
  std::vector<double> dx = {30, 31, 29, 30.5, 29.5, 30, 31, 29};
  std::vector<double> dy = {6, 5.5, 6.5, 6, 5, 7, 6, 6};
  for (int i = 0; i < 9; ++i) {
    dx.push_back(-50.0 + 0.5 * i);
    dy.push_back(-80.0 + 20.0 * i);
  }
  EXPECT_NEAR(VoteShift(dx, 10.0, 5).dx_px, -48.0, 3.0);
  const ShiftEstimate e = VoteShift2D(dx, dy, 10.0, 10.0, 5);
  EXPECT_TRUE(e.ok);
  EXPECT_NEAR(e.dx_px, 30.0, 1.0);
  EXPECT_EQ(e.inliers, 8);
  EXPECT_EQ(e.matches, 17);
  // bin_dy_px 0: the vote on dx alone.
  EXPECT_DOUBLE_EQ(VoteShift2D(dx, dy, 10.0, 0.0, 5).dx_px, VoteShift(dx, 10.0, 5).dx_px);
}

TEST(EstimateShift, TurningLeftMovesTheSceneRightInTheImage) {
  // dx = x_in_current - x_in_reference: a robot that turned left by 5 degrees sees the scene
  // about fx * tan(5 deg) = 24 px further right.
  const sim::Scenario s = sim::LoadScenario("table1_almost_straight");
  sim::Simulation a(s.world, s.camera, {}, 1);
  sim::Simulation b(s.world, s.camera, {}, 1);
  a.AddRobot(Pose2{1.0, 0.0, 0.0}, s.robot);
  b.AddRobot(Pose2{1.0, 0.0, DegToRad(5.0)}, s.robot);
  const ShiftEstimate e = EstimateShift(a.RenderClean(0), b.RenderClean(0), ShiftOptions{});
  ASSERT_TRUE(e.ok);
  EXPECT_NEAR(e.dx_px, s.camera.model.fx * std::tan(DegToRad(5.0)), 3.0);
}

struct Stromovka {
  std::string dir;
  std::map<std::pair<int, int>, double> offset;  // (place, session) -> x_session - x_session01
};

Stromovka LoadOffsets(const std::string& dir) {
  Stromovka data{dir, {}};
  std::ifstream in(dir + "/offsets.txt");
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream fields(line);
    int place = 0, session = 0;
    double dx = 0;
    fields >> place >> session >> dx;
    data.offset[{place, session}] = dx;
  }
  return data;
}

// Fraction of ordered session pairs (same place) whose estimated shift is within 17.5 px of the
// ground truth.
double FractionWithin(const Stromovka& data, double tolerance_px) {
  const ShiftOptions options;
  const FeatureExtractor extractor(options.features);
  std::map<std::pair<int, int>, Features> features;
  for (const auto& [key, dx] : data.offset) {
    char name[32];
    std::snprintf(name, sizeof(name), "/%02d%02d.png", key.second, key.first);
    const cv::Mat img = io::ReadImage(data.dir + name, cv::IMREAD_GRAYSCALE);
    EXPECT_FALSE(img.empty()) << data.dir + name;
    features[key] = extractor.Extract(img);
  }
  int good = 0, total = 0;
  for (const auto& [a, off_a] : data.offset) {
    for (const auto& [b, off_b] : data.offset) {
      if (a.first != b.first || a.second == b.second) continue;
      const ShiftEstimate e = EstimateShift(features[a], features[b], options);
      ++total;
      if (e.ok && std::abs(e.dx_px - (off_b - off_a)) <= tolerance_px) ++good;
    }
  }
  return total > 0 ? static_cast<double>(good) / total : 0.0;
}

TEST(EstimateShift, SeasonalPairsInTheBundledStromovkaSubset) {
  const Stromovka data = LoadOffsets(std::string(MAPLESS_SOURCE_DIR) + "/tests/data/stromovka");
  ASSERT_EQ(data.offset.size(), 6u);
  EXPECT_GE(FractionWithin(data, 17.5), 0.8);  // 12 ordered pairs
}

TEST(EstimateShift, StromovkaAllSessionPairsWithin17Px) {
  const std::string dir = std::string(MAPLESS_SOURCE_DIR) + "/../shared/data/stromovka_sessions";
  if (!std::filesystem::exists(dir + "/offsets.txt")) {
    GTEST_SKIP() << "shared data not found at " << dir << " (the bundled subset is tested above)";
  }
  const Stromovka data = LoadOffsets(dir);
  ASSERT_EQ(data.offset.size(), 60u);
  const double fraction = FractionWithin(data, 17.5);
  std::printf("stromovka: %.3f of 660 ordered session pairs within 17.5 px\n", fraction);
  // The default (upright AKAZE + SIFT, cross-checked, (dx, dy) vote): 0.986; stock FAST + SIFT
  // with a dx vote, the best baseline of `mapless eval shift`: 0.974.
  EXPECT_GE(fraction, 0.98);
}

}  // namespace
}  // namespace mapless::features
