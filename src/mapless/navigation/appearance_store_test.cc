// The appearance route store (route/appearance_store.h) with the leader that writes it: a route
// read back and replayed through AppearanceLeader::AddStored gives exactly the leader's model, and
// a teach cut short leaves a route that loads with every whole image.
#include "mapless/route/appearance_store.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <opencv2/imgproc.hpp>

#include "mapless/core/check.h"
#include "mapless/io/atomic_file.h"
#include "mapless/navigation/appearance.h"
#include "mapless/navigation/appearance_experiences.h"
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
        writer.Append({leader.last_low(), leader.distance_m(), f.odometry, {}});
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
    writer.Append({low, 0.0, Pose2{}, {}});
    writer.Append({low, 0.2, Pose2{0.2, 0.0, 0.0}, {}});
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

// Issue 45: learned views are written as version 2 (view files first, then the manifest), read
// back with the route, rebuild a model whose columns are the images' then the views', and are
// pruned least recently used first, their files removed.
TEST(AppearanceStore, LearnedViewsRoundTripRebuildAndArePrunedLeastRecentlyUsedFirst) {
  const std::string dir = FreshDir("views");
  {
    route::AppearanceRouteWriter writer(dir, 320, 240, 64, 64);
    for (int i = 0; i < 4; ++i)
      writer.Append(
          {cv::Mat(64, 64, CV_8UC1, cv::Scalar(40 + 30 * i)), 0.2 * i, Pose2{0.2 * i, 0, 0}, {}});
    writer.Finish();
  }
  route::StoredAppearanceRoute stored = route::LoadAppearanceRoute(dir);
  EXPECT_EQ(stored.visits, 0);
  AppearanceExperienceOptions options;
  options.max_views = 3;  // two learned views a place
  auto view = [](int place, int grey, double offset) {
    LearnedAppearanceView v;
    v.place = place;
    v.low = cv::Mat(64, 64, CV_8UC1, cv::Scalar(grey));
    cv::circle(v.low, {20 + place, 30}, 9, cv::Scalar(255 - grey), -1);
    v.offset_px = offset;
    return v;
  };
  for (int visit = 1; visit <= 3; ++visit) {
    std::vector<LearnedAppearanceView> learned{view(1, 100 + visit, 1.5 * visit)};
    if (visit == 1) learned.push_back(view(3, 20, -2.0));
    // Visit 3 steers place 1 by its first learned view: the second is then the least recently
    // used and makes room.
    const std::vector<int> used{0, visit == 3 ? 1 : 0, -1, 0};
    EXPECT_EQ(ApplyAppearanceVisit(&stored, used, learned, options),
              static_cast<int>(learned.size()));
    route::SaveAppearanceViews(dir, &stored);
  }
  const route::StoredAppearanceRoute back = route::LoadAppearanceRoute(dir);
  EXPECT_EQ(back.visits, 3);
  EXPECT_EQ(back.views(), 3);
  ASSERT_EQ(back.images[1].views.size(), 2u);
  EXPECT_EQ(back.images[1].views[0].learned_at, 1);
  EXPECT_EQ(back.images[1].views[0].last_used, 3);
  EXPECT_EQ(back.images[1].views[1].learned_at, 3);
  EXPECT_DOUBLE_EQ(back.images[1].views[1].offset_px, 4.5);
  EXPECT_EQ(cv::norm(back.images[1].views[1].low, view(1, 103, 0).low, cv::NORM_INF), 0.0);
  EXPECT_FALSE(std::filesystem::exists(dir + "/views/000001-visit-0002.png"));  // pruned
  EXPECT_TRUE(std::filesystem::exists(dir + "/views/000003-visit-0001.png"));
  EXPECT_NE(io::ReadFile(dir + "/appearance.json", 1 << 20).find("\"version\": 2"),
            std::string::npos);

  const auto model = BuildStoredAppearanceRoute(back, AppearanceLeaderOptions{});
  ASSERT_EQ(model->size(), 4);
  ASSERT_EQ(model->columns(), 7);
  EXPECT_EQ(model->ColumnsOf(1), (std::vector<int>{1, 4, 5}));
  EXPECT_EQ(model->ColumnsOf(3), (std::vector<int>{3, 6}));
  EXPECT_EQ(model->PlaceOf(6), 3);
  EXPECT_DOUBLE_EQ(model->OffsetOf(5), 4.5);
  EXPECT_DOUBLE_EQ(model->OffsetOf(2), 0.0);

  EXPECT_EQ(PruneAppearanceViews(&stored, 1), 3);
  EXPECT_EQ(stored.views(), 0);
  EXPECT_THROW(PruneAppearanceViews(&stored, 0), InputError);
}

TEST(AppearanceStore, BadViewsAreRefusedNamingTheField) {
  auto refused = [](const std::string& views, const std::string& needle, int version = 2) {
    const std::string text =
        R"({"format": "mapless-appearance-route", "version": )" + std::to_string(version) +
        R"(, "visits": 2, "image_width": 320, "image_height": 240, "low_width": 64,
            "low_height": 64, "complete": true,
            "images": [{"index": 0, "distance_m": 0, "x_m": 0, "y_m": 0, "theta_rad": 0,
                        "file": "images/000000.png", "views": )" +
        views + "}]}";
    try {
      route::ParseAppearanceManifest(text, "a.json", nullptr);
      ADD_FAILURE() << "accepted " << views;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    }
  };
  const std::string good =
      R"({"file": "views/000000-visit-0001.png", "offset_px": 1, "learned_at": 1,
          "last_used": 2})";
  EXPECT_EQ(route::ParseAppearanceManifest(
                R"({"format": "mapless-appearance-route", "version": 2, "visits": 2,
                    "image_width": 320, "image_height": 240, "low_width": 64, "low_height": 64,
                    "complete": true, "images": [{"index": 0, "distance_m": 0, "x_m": 0,
                    "y_m": 0, "theta_rad": 0, "file": "images/000000.png", "views": [)" +
                    good + "]}]}",
                "a.json", nullptr)
                .views(),
            1);
  refused("[" + good + "]", "only a version 2 route", 1);
  refused("{}", "not a list");
  refused(R"([{"file": "../../x.png", "offset_px": 1, "learned_at": 1, "last_used": 1}])", "file");
  refused(R"([{"file": "views/000000-visit-0003.png", "offset_px": 1, "learned_at": 3,
               "last_used": 3}])",
          "learned_at");
  refused(R"([{"file": "views/000000-visit-0002.png", "offset_px": 1, "learned_at": 2,
               "last_used": 1}])",
          "last_used");
  refused(R"([{"file": "views/000000-visit-0001.png", "offset_px": 1e30, "learned_at": 1,
               "last_used": 1}])",
          "offset_px");
  refused("[" + good + "," + good + "]", "two views");
}

}  // namespace
}  // namespace mapless::navigation
