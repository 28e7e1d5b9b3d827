// The appearance route store (route/appearance_store.h) with the leader that writes it: a route
// read back and replayed through AppearanceLeader::AddStored gives exactly the leader's model, and
// a teach cut short leaves a route that loads with every whole image.
#include "mapless/route/appearance_store.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "mapless/core/check.h"
#include "mapless/navigation/appearance.h"
#include "mapless/sim/driver.h"
#include "mapless/sim/scenario.h"
#include "mapless/sim/simulation.h"

namespace mapless::navigation {
namespace {

std::string FreshDir(const std::string& name) {
  const std::string dir = ::testing::TempDir() + "mapless_appearance_" + name;
  std::filesystem::remove_all(dir);
  return dir;
}

TEST(AppearanceStore, ARouteReadBackRebuildsTheLeadersModelExactly) {
  const sim::Scenario scenario = sim::LoadScenario("office_aliasing");
  const std::string dir = FreshDir("rebuild");
  AppearanceLeader leader;
  route::AppearanceRouteWriter writer(dir, 320, 240, 64, 64);
  sim::DriveOptions drive;
  int frames = 0;
  struct Enough {};  // the first 150 frames of the drive are the route here
  try {
    sim::DriveTaughtPath(scenario, drive, [&](const sim::DriveFrame& f) {
      if (++frames > 150) throw Enough{};
      if (leader.Update(f.image, f.odometry))
        writer.Append({leader.last_low(), leader.distance_m(), f.odometry});
    });
  } catch (const Enough&) {
  }
  leader.Finish();
  writer.Finish();
  const auto original = leader.Snapshot();
  ASSERT_GE(original->size(), 10);

  const route::StoredAppearanceRoute stored = route::LoadAppearanceRoute(dir);
  EXPECT_TRUE(stored.complete);
  ASSERT_EQ(static_cast<int>(stored.images.size()), original->size());
  AppearanceLeader replay;
  for (const auto& image : stored.images)
    replay.AddStored(image.low, image.distance_m, image.odometry);
  replay.Finish();
  const auto rebuilt = replay.Snapshot();
  ASSERT_EQ(rebuilt->size(), original->size());
  EXPECT_EQ(rebuilt->complete, original->complete);
  // Bit for bit: the same images in the same order through the same incremental PCA.
  EXPECT_EQ((rebuilt->space.mean - original->space.mean).cwiseAbs().maxCoeff(), 0.0f);
  EXPECT_EQ((rebuilt->space.basis - original->space.basis).cwiseAbs().maxCoeff(), 0.0f);
  EXPECT_EQ((rebuilt->space.projections - original->space.projections).cwiseAbs().maxCoeff(), 0.0f);
  for (int i = 0; i < rebuilt->size(); ++i) {
    EXPECT_EQ(rebuilt->images[static_cast<std::size_t>(i)]->distance_m,
              original->images[static_cast<std::size_t>(i)]->distance_m);
  }
}

TEST(AppearanceStore, ATeachCutShortLoadsIncompleteAndBadManifestsAreNamed) {
  const std::string dir = FreshDir("cut");
  {
    route::AppearanceRouteWriter writer(dir, 320, 240, 64, 64);
    cv::Mat low(64, 64, CV_8UC1, cv::Scalar(90));
    writer.Append({low, 0.0, Pose2{}});
    writer.Append({low, 0.2, Pose2{0.2, 0.0, 0.0}});
    // No Finish(): the process "died" here.
  }
  const route::StoredAppearanceRoute cut = route::LoadAppearanceRoute(dir);
  EXPECT_FALSE(cut.complete);
  EXPECT_EQ(cut.images.size(), 2u);
  EXPECT_THROW(route::AppearanceRouteWriter(dir, 320, 240, 64, 64), InputError);

  auto refused = [](const std::string& text, const std::string& needle) {
    try {
      route::ParseAppearanceManifest(text, "a.json", nullptr);
      ADD_FAILURE() << "accepted " << text;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    }
  };
  refused("[]", "not a JSON object");
  refused(R"({"format": "mapless-route"})", "format");
  refused(R"({"format": "mapless-appearance-route", "version": 7})", "version");
  refused(R"({"format": "mapless-appearance-route", "version": 1, "image_width": 320,
              "image_height": 240, "low_width": 64, "low_height": 64, "complete": true,
              "images": [{"index": 0, "distance_m": 1, "x_m": 0, "y_m": 0, "theta_rad": 0,
                          "file": "images/000000.png"},
                         {"index": 1, "distance_m": 0.5, "x_m": 0, "y_m": 0, "theta_rad": 0,
                          "file": "images/000001.png"}]})",
          "backwards");
  refused(R"({"format": "mapless-appearance-route", "version": 1, "image_width": 320,
              "image_height": 240, "low_width": 64, "low_height": 64, "complete": true,
              "images": [{"index": 0, "distance_m": 0, "x_m": 0, "y_m": 0, "theta_rad": 0,
                          "file": "../../etc/passwd"}]})",
          "file");
}

}  // namespace
}  // namespace mapless::navigation
