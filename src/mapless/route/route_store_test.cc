#include "mapless/route/route_store.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>

#include "mapless/core/check.h"
#include "mapless/core/rng.h"
#include "mapless/core/testing.h"
#include "mapless/io/atomic_file.h"
#include "mapless/route/appearance_store.h"

namespace mapless::route {
namespace {

std::string FreshDir(const std::string& name) {
  const std::string dir = ::testing::TempDir() + "mapless_route_" + name;
  std::filesystem::remove_all(dir);
  return dir;
}

Keyframe MakeKeyframe(int index) {
  Rng rng(static_cast<std::uint64_t>(index) + 1);
  Keyframe kf;
  kf.index = index;
  kf.t_ns = 100'000'000LL * index;
  kf.thumbnail = cv::Mat(60, 80, CV_8UC1, cv::Scalar(10 * index));
  for (int i = 0; i < 50; ++i) {
    kf.keypoints.emplace_back(static_cast<float>(rng.Uniform(0, 320)),
                              static_cast<float>(rng.Uniform(0, 240)), 31.0f);
  }
  kf.descriptors = cv::Mat(50, 32, CV_8UC1);
  for (int r = 0; r < 50; ++r) {
    for (int c = 0; c < 32; ++c)
      kf.descriptors.at<std::uint8_t>(r, c) = static_cast<std::uint8_t>(rng.UniformInt(256));
  }
  if (index > 0) {
    kf.segment_start_px = {{10, 20}, {30, 40}};
    kf.segment_end_px = {{12, 21}, {35, 41}};
  }
  // A teach with odometry stores the pose (odd indices here), one without does not.
  if (index % 2 == 1) kf.odometry = Pose2{0.5 * index, -0.25 * index, 0.1 * index + 0.0123456789};
  return kf;
}

TEST(RouteStore, RoundTripsEveryField) {
  const std::string dir = FreshDir("roundtrip");
  RouteWriter writer(dir, "orb", 320, 240);
  for (int i = 0; i < 3; ++i) writer.Append(MakeKeyframe(i));
  writer.Finish();
  const Route route = LoadRoute(dir);
  EXPECT_TRUE(route.complete);
  EXPECT_EQ(route.detector, "orb");
  EXPECT_EQ(route.image_width, 320);
  ASSERT_EQ(route.keyframes.size(), 3u);
  for (int i = 0; i < 3; ++i) {
    const Keyframe expected = MakeKeyframe(i);
    const Keyframe& got = route.keyframes[static_cast<std::size_t>(i)];
    EXPECT_EQ(got.index, i);
    EXPECT_EQ(got.t_ns, expected.t_ns);
    ASSERT_EQ(got.keypoints.size(), expected.keypoints.size());
    EXPECT_FLOAT_EQ(got.keypoints[7].pt.x, expected.keypoints[7].pt.x);
    EXPECT_EQ(cv::norm(got.descriptors, expected.descriptors, cv::NORM_INF), 0.0);
    EXPECT_EQ(got.segment_end_px, expected.segment_end_px);
    EXPECT_EQ(cv::norm(got.thumbnail, expected.thumbnail, cv::NORM_INF), 0.0);
    ASSERT_EQ(got.odometry.has_value(), expected.odometry.has_value()) << i;
    if (got.odometry) {
      // Stored to the micrometre and the nanoradian.
      EXPECT_NEAR(got.odometry->x_m, expected.odometry->x_m, 0.5e-6);
      EXPECT_NEAR(got.odometry->y_m, expected.odometry->y_m, 0.5e-6);
      EXPECT_NEAR(got.odometry->theta_rad, expected.odometry->theta_rad, 0.5e-9);
      EXPECT_NE(got.odometry->theta_rad, expected.odometry->theta_rad);  // 0.1123456789 rounded
    }
  }
}

// The manifest is written a keyframe at a time (issue 41: each entry's text made once); it must be
// the bytes nlohmann writes for the whole document, at every length and when finished.
TEST(RouteStore, TheManifestIsWhatTheWholeDocumentDumpsTo) {
  const std::string dir = FreshDir("manifest_text");
  RouteWriter writer(dir, "orb", 640, 480);
  const auto check = [&](const std::string& when) {
    const std::string text = io::ReadFile(dir + "/manifest.json", 1 << 20);
    EXPECT_EQ(text, nlohmann::json::parse(text).dump(1) + "\n") << when;
  };
  check("empty");
  for (int i = 0; i < 4; ++i) {
    writer.Append(MakeKeyframe(i));
    check(std::to_string(i + 1) + " keyframes");
  }
  writer.Finish();
  check("finished");
  EXPECT_EQ(LoadRoute(dir).keyframes.size(), 4u);
  // The appearance route's manifest, the same way, also after a reopened writer goes on.
  const std::string adir = FreshDir("manifest_text_appearance");
  const auto check_appearance = [&](const std::string& when) {
    const std::string text = io::ReadFile(adir + "/appearance.json", 1 << 20);
    EXPECT_EQ(text, nlohmann::json::parse(text).dump(1) + "\n") << when;
  };
  const auto image = [](int i) {
    return StoredAppearanceImage{cv::Mat(64, 64, CV_8UC1, cv::Scalar(3 * i)),
                                 0.25 * i,
                                 Pose2{0.25 * i, 0.01 * i, 0.003 * i},
                                 {}};
  };
  {
    AppearanceRouteWriter images(adir, 320, 240, 64, 64);
    check_appearance("empty");
    for (int i = 0; i < 3; ++i) images.Append(image(i));
    check_appearance("3 images");
  }
  std::unique_ptr<AppearanceRouteWriter> reopened = AppearanceRouteWriter::Reopen(adir);
  reopened->Append(image(3));
  check_appearance("reopened, 4 images");
  reopened->Finish();
  check_appearance("finished");
  EXPECT_EQ(LoadAppearanceRoute(adir).images.size(), 4u);
}

TEST(RouteStore, AnUnfinishedTeachLoadsWithItsCompletedKeyframes) {
  const std::string dir = FreshDir("unfinished");
  RouteWriter writer(dir, "orb", 320, 240);
  writer.Append(MakeKeyframe(0));
  writer.Append(MakeKeyframe(1));
  // No Finish(): as if the teach was killed here. A half-written next keyframe (no manifest entry
  // yet) must not matter either.
  io::WriteFileAtomic(dir + "/keyframes/000002.yml", "format: mapless-keyfr");
  const Route route = LoadRoute(dir);
  EXPECT_FALSE(route.complete);
  EXPECT_EQ(route.keyframes.size(), 2u);
}

TEST(RouteStore, RefusesToOverwriteAnExistingRoute) {
  const std::string dir = FreshDir("overwrite");
  { RouteWriter writer(dir, "orb", 320, 240); }
  EXPECT_NE(testing::InputErrorOf([&] {
              RouteWriter again(dir, "orb", 320, 240);
            }).find("already holds a route"),
            std::string::npos);
}

TEST(RouteStore, TruncatedKeyframeFileIsNamedInTheError) {
  const std::string dir = FreshDir("truncated");
  RouteWriter writer(dir, "orb", 320, 240);
  writer.Append(MakeKeyframe(0));
  writer.Append(MakeKeyframe(1));
  const std::string path = dir + "/keyframes/000001.yml";
  const std::string text = io::ReadFile(path, 1 << 24);
  io::WriteFileAtomic(path, text.substr(0, text.size() / 2));
  const std::string err = testing::InputErrorOf([&] { LoadRoute(dir); });
  EXPECT_NE(err.find("000001.yml"), std::string::npos) << err;
}

TEST(RouteStore, CorruptOrMissingFilesGiveOneClearError) {
  const std::string dir = FreshDir("corrupt");
  RouteWriter writer(dir, "orb", 320, 240);
  writer.Append(MakeKeyframe(0));
  writer.Append(MakeKeyframe(1));
  const std::string good = io::ReadFile(dir + "/keyframes/000000.yml", 1 << 24);
  // Garbage keyframe data.
  io::WriteFileAtomic(dir + "/keyframes/000000.yml", std::string("\x01\x02garbage\xff", 11));
  EXPECT_NE(testing::InputErrorOf([&] { LoadRoute(dir); }).find("000000.yml"), std::string::npos);
  io::WriteFileAtomic(dir + "/keyframes/000000.yml", good);
  // Missing thumbnail.
  std::filesystem::remove(dir + "/keyframes/000001.png");
  EXPECT_NE(testing::InputErrorOf([&] { LoadRoute(dir); }).find("000001.png"), std::string::npos);
  // Corrupt manifest.
  io::WriteFileAtomic(dir + "/manifest.json", "{\"format\": \"mapless-route\", \"vers");
  EXPECT_NE(testing::InputErrorOf([&] { LoadRoute(dir); }).find("manifest.json: corrupt manifest"),
            std::string::npos);
  // No route at all.
  EXPECT_NE(
      testing::InputErrorOf([&] { LoadRoute(dir + "/nothing"); }).find("manifest.json is missing"),
      std::string::npos);
}

TEST(RouteStore, AManifestCannotPointOutsideTheRoute) {
  const std::string manifest =
      R"({"format": "mapless-route", "version": 1, "detector": "orb", "image_width": 320,
          "image_height": 240, "complete": true, "keyframes": [{"index": 0, "t_s": 0.0,
          "data": "../../secret.yml", "thumbnail": "keyframes/000000.png"}]})";
  EXPECT_NE(testing::InputErrorOf([&] {
              ParseManifest(manifest, "m.json");
            }).find("m.json: keyframe 0 names a file outside the route directory"),
            std::string::npos);
  EXPECT_NE(testing::InputErrorOf([&] { ParseManifest("[1, 2]", "m.json"); }).find("m.json"),
            std::string::npos);
}

TEST(RouteStore, NewerFormatVersionIsRefusedByName) {
  const std::string dir = FreshDir("version");
  { RouteWriter writer(dir, "orb", 320, 240); }
  std::string manifest = io::ReadFile(dir + "/manifest.json", 1 << 24);
  manifest.replace(manifest.find("\"version\": 1"), 12, "\"version\": 9");
  io::WriteFileAtomic(dir + "/manifest.json", manifest);
  EXPECT_NE(testing::InputErrorOf([&] {
              LoadRoute(dir);
            }).find("route format version 9 is not supported"),
            std::string::npos);
}

KeyframeView MakeView(int keyframe, int learned_at, double offset_px) {
  const Keyframe source = MakeKeyframe(keyframe + 100 * learned_at);
  KeyframeView v;
  v.keypoints = source.keypoints;
  v.descriptors = source.descriptors;
  v.offset_px = offset_px;
  v.learned_at = learned_at;
  v.last_used = learned_at;
  return v;
}

// Learned views (issue 45): written beside the keyframes, listed by a version-2 manifest, loaded
// back with every field; a pruned view's file goes; a reader of version 1 only is refused by name.
TEST(RouteStore, LearnedViewsRoundTripAndPrunedOnesLeaveNoFile) {
  const std::string dir = FreshDir("views");
  {
    RouteWriter writer(dir, "orb", 320, 240);
    for (int i = 0; i < 3; ++i) writer.Append(MakeKeyframe(i));
    writer.Finish();
  }
  Route route = LoadRoute(dir);
  EXPECT_EQ(route.visits, 0);
  route.visits = 2;
  route.keyframes[1].views = {MakeView(1, 1, 12.5), MakeView(1, 2, -3.25)};
  route.keyframes[1].views[0].last_used = 2;
  SaveViews(dir, &route);
  const std::string first_file = route.keyframes[1].views[0].file;
  EXPECT_EQ(first_file, "keyframes/000001-visit-0001.yml");
  Route loaded = LoadRoute(dir);
  EXPECT_EQ(loaded.visits, 2);
  EXPECT_TRUE(loaded.keyframes[0].views.empty());
  ASSERT_EQ(loaded.keyframes[1].views.size(), 2u);
  const KeyframeView& v = loaded.keyframes[1].views[0];
  EXPECT_EQ(v.offset_px, 12.5);
  EXPECT_EQ(v.learned_at, 1);
  EXPECT_EQ(v.last_used, 2);
  EXPECT_EQ(cv::norm(v.descriptors, route.keyframes[1].views[0].descriptors, cv::NORM_INF), 0.0);
  ASSERT_EQ(v.keypoints.size(), route.keyframes[1].views[0].keypoints.size());
  EXPECT_EQ(v.keypoints[7].pt, route.keyframes[1].views[0].keypoints[7].pt);
  // The first view pruned, a third learned: its file goes, the others stay.
  loaded.visits = 3;
  loaded.keyframes[1].views.erase(loaded.keyframes[1].views.begin());
  loaded.keyframes[2].views = {MakeView(2, 3, 40.0)};
  // A file of the user's whose name merely contains "-visit-" is not mapless's to remove.
  const std::string users = dir + "/keyframes/my-visit-notes.yml";
  std::ofstream(users) << "notes\n";
  SaveViews(dir, &loaded);
  EXPECT_FALSE(std::filesystem::exists(dir + "/" + first_file));
  EXPECT_TRUE(std::filesystem::exists(users));
  EXPECT_TRUE(IsViewFileName("000001-visit-0001.yml", ".yml"));
  EXPECT_TRUE(IsViewFileName("000001-visit-1000000.yml", ".yml"));
  EXPECT_FALSE(IsViewFileName("000001-visit-0001.yml.bak", ".yml"));
  EXPECT_FALSE(IsViewFileName("00001x-visit-0001.yml", ".yml"));
  EXPECT_FALSE(IsViewFileName("000001-visit-.yml", ".yml"));
  std::filesystem::remove(users);
  const Route again = LoadRoute(dir);
  EXPECT_EQ(again.keyframes[1].views.size(), 1u);
  EXPECT_EQ(again.keyframes[1].views[0].offset_px, -3.25);
  EXPECT_EQ(again.keyframes[2].views.size(), 1u);
  // A route with views is not reopened by a teach or a copy.
  EXPECT_NE(testing::InputErrorOf([&] { RouteWriter::Reopen(dir); }).find("learned views"),
            std::string::npos);
}

TEST(RouteStore, AViewOutsideTheRouteOrItsVisitsIsRefused) {
  const std::string dir = FreshDir("bad_views");
  {
    RouteWriter writer(dir, "orb", 320, 240);
    for (int i = 0; i < 2; ++i) writer.Append(MakeKeyframe(i));
    writer.Finish();
  }
  Route route = LoadRoute(dir);
  route.visits = 1;
  route.keyframes[1].views = {MakeView(1, 1, 5.0)};
  SaveViews(dir, &route);
  const std::string good = io::ReadFile(dir + "/manifest.json", 1 << 24);
  const auto refused = [&](const std::string& from, const std::string& to) {
    std::string m = good;
    m.replace(m.find(from), from.size(), to);
    return testing::InputErrorOf([&] { ParseManifest(m, "m.json"); });
  };
  EXPECT_NE(refused("\"keyframes/000001-visit-0001.yml\"", "\"../x.yml\"").find("outside"),
            std::string::npos);
  EXPECT_NE(refused("\"learned_at\": 1", "\"learned_at\": 7").find("visits"), std::string::npos);
  EXPECT_NE(refused("\"offset_px\": 5.0", "\"offset_px\": 1e300").find("offset_px"),
            std::string::npos);
  std::filesystem::remove(dir + "/keyframes/000001-visit-0001.yml");
  EXPECT_NE(testing::InputErrorOf([&] { LoadRoute(dir); }).find("view file is missing"),
            std::string::npos);
}

// Everything a repeat relies on is checked on loading, naming the file.
TEST(RouteStore, LoadingCatchesWhatARepeatWouldTripOn) {
  const auto route_with = [](const std::string& name, const std::string& detector,
                             const std::function<void(Keyframe*)>& edit) {
    const std::string dir = FreshDir(name);
    RouteWriter writer(dir, detector, 320, 240);
    for (int i = 0; i < 3; ++i) {
      Keyframe kf = MakeKeyframe(i);
      if (i == 2) edit(&kf);
      writer.Append(kf);
    }
    writer.Finish();
    return testing::InputErrorOf([&] { LoadRoute(dir); });
  };
  const auto none = [](Keyframe*) {};
  EXPECT_NE(route_with("unknown_detector", "surf", none).find("manifest.json: detector: unknown"),
            std::string::npos);
  EXPECT_NE(route_with("sift_with_orb", "sift", none).find("000000.yml: descriptors of 32 bytes"),
            std::string::npos);
  EXPECT_NE(route_with("backwards", "orb", [](Keyframe* kf) { kf->t_ns = 50'000'000; })
                .find("000002.yml: t_ns 50000000 is not after"),
            std::string::npos);
  EXPECT_NE(route_with("outside", "orb", [](Keyframe* kf) { kf->keypoints[3].pt.x = 900.f; })
                .find("000002.yml: keypoint (900"),
            std::string::npos);
  EXPECT_EQ(route_with("fine", "orb", none), "");
  {
    const std::string dir = FreshDir("one_keyframe");
    RouteWriter writer(dir, "orb", 320, 240);
    writer.Append(MakeKeyframe(0));
    writer.Finish();
    EXPECT_NE(testing::InputErrorOf([&] { LoadRoute(dir); }).find("at least 2"), std::string::npos);
  }
}

}  // namespace
}  // namespace mapless::route

namespace mapless::route {
namespace {

// Issue 40: t_ns is a whole number, all of it ("0.5" was read as 0 and "12abc" as 12).
TEST(RouteStore, AKeyframeTimeThatIsNotAWholeNumberIsRefused) {
  const std::string text = SerializeKeyframe(MakeKeyframe(1));
  const std::size_t at = text.find("t_ns: \"");
  ASSERT_NE(at, std::string::npos);
  const std::size_t end = text.find('"', at + 7);
  for (const std::string bad : {"0.5", "12abc", "1e3", "", " 7", "99999999999999999999"}) {
    const std::string edited = text.substr(0, at + 7) + bad + text.substr(end);
    try {
      ParseKeyframe(edited, "kf.yml");
      ADD_FAILURE() << "accepted t_ns '" << bad << "'";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("t_ns"), std::string::npos) << e.what();
    }
  }
}

// ParseKeyframe reads a file as the route store writes it with a fast reader, and anything else
// with yaml-cpp: both must give the same keyframe (a comment line makes the file non-canonical).
TEST(RouteStore, TheFastKeyframeReaderAgreesWithYamlCpp) {
  for (int index : {0, 1, 5}) {
    Keyframe kf = MakeKeyframe(index);
    if (index == 5) {
      kf.keypoints.clear();
      kf.descriptors = cv::Mat();
      kf.segment_start_px.clear();
      kf.segment_end_px.clear();
    }
    const std::string text = SerializeKeyframe(kf);
    const Keyframe fast = ParseKeyframe(text, "fast");
    const Keyframe general = ParseKeyframe(text + "# not canonical\n", "general");
    ASSERT_EQ(fast.keypoints.size(), general.keypoints.size());
    for (std::size_t i = 0; i < fast.keypoints.size(); ++i) {
      EXPECT_EQ(fast.keypoints[i].pt, general.keypoints[i].pt);
      EXPECT_EQ(fast.keypoints[i].size, general.keypoints[i].size);
      EXPECT_EQ(fast.keypoints[i].angle, general.keypoints[i].angle);
      EXPECT_EQ(fast.keypoints[i].response, general.keypoints[i].response);
      EXPECT_EQ(fast.keypoints[i].octave, general.keypoints[i].octave);
      EXPECT_EQ(fast.keypoints[i].class_id, general.keypoints[i].class_id);
    }
    EXPECT_EQ(fast.index, general.index);
    EXPECT_EQ(fast.t_ns, general.t_ns);
    EXPECT_EQ(cv::norm(fast.descriptors, general.descriptors, cv::NORM_INF), 0.0);
    EXPECT_EQ(fast.descriptors.type(), general.descriptors.type());
    EXPECT_EQ(fast.segment_start_px, general.segment_start_px);
    EXPECT_EQ(fast.segment_end_px, general.segment_end_px);
    ASSERT_EQ(fast.odometry.has_value(), index % 2 == 1);
    ASSERT_EQ(general.odometry.has_value(), index % 2 == 1);
    if (fast.odometry) {
      EXPECT_DOUBLE_EQ(fast.odometry->x_m, general.odometry->x_m);
      EXPECT_DOUBLE_EQ(fast.odometry->theta_rad, general.odometry->theta_rad);
    }
    // Cut anywhere, the file is refused (by one reader or the other), never half read.
    for (std::size_t n = 0; n + 1 < text.size(); n += 97)
      EXPECT_THROW(ParseKeyframe(text.substr(0, n), "cut"), InputError) << n;
  }
}

TEST(RouteStore, ABadOdometryFieldIsNamed) {
  const std::string text = SerializeKeyframe(MakeKeyframe(1));
  const std::size_t at = text.find("odometry: ");
  ASSERT_NE(at, std::string::npos);
  const std::size_t line_end = text.find(']', at) + 1;  // OpenCV may wrap the list
  for (const char* bad : {"odometry: [ 1., 2. ]", "odometry: [ 1., .nan, 3. ]", "odometry: x"}) {
    const std::string broken = text.substr(0, at) + bad + text.substr(line_end);
    try {
      ParseKeyframe(broken, "kf.yml");
      ADD_FAILURE() << bad << " was accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("odometry"), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace mapless::route
