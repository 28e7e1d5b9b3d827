#include "mapless/live/feed.h"

#include <gtest/gtest.h>

#include <map>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "mapless/rosmsg/messages.h"

namespace mapless::live {
namespace {

FrameView AFrame(int i) {
  FrameView f;
  f.method = "repeat";
  f.frame = i;
  f.observation.image = cv::Mat(240, 320, CV_8UC1);
  cv::randu(f.observation.image, 0, 255);
  f.observation.t_ns = 1'000'000'000LL + i * 100'000'000LL;
  f.observation.odometry = Pose2{0.1 * i, 0.0, 0.0};
  f.decision.state = robot::MethodState::kDriving;
  f.decision.status = "driving";
  f.command = {0.2, 0.05};
  f.decision.command = f.command;
  return f;
}

std::map<std::uint32_t, std::string> ByChannel(const std::vector<Outgoing>& out) {
  std::map<std::uint32_t, std::string> m;
  for (const Outgoing& o : out) m[o.channel_id] = o.payload;
  return m;
}

TEST(LiveFeed, AFrameIsEveryChannelInItsEncoding) {
  Feed feed({{0, 0, 0}, {1, 0, 0}});
  const auto m = ByChannel(feed.Messages(AFrame(0)));
  for (std::uint32_t id : {kCameraChannel, kDebugChannel, kDecisionChannel, kTfChannel,
                           kPathChannel, kRouteChannel, kOdomChannel, kCmdVelChannel})
    EXPECT_EQ(m.count(id), 1u) << id;
  const rosmsg::CompressedImageFields img =
      rosmsg::DecodeCompressedImage(m.at(kCameraChannel), rosmsg::Wire::kCdr);
  EXPECT_EQ(img.format, "jpeg");
  EXPECT_EQ(img.header.stamp_ns, 1'000'000'000LL);
  EXPECT_EQ(static_cast<unsigned char>(img.data[0]), 0xff);  // JPEG's start of image
  const auto decision = nlohmann::json::parse(m.at(kDecisionChannel));
  EXPECT_EQ(decision["state"], "driving");
  EXPECT_DOUBLE_EQ(decision["v_mps"].get<double>(), 0.2);
  const auto tf = nlohmann::json::parse(m.at(kTfChannel));
  EXPECT_EQ(tf["transforms"][0]["parent_frame_id"], "odom");
  EXPECT_EQ(tf["transforms"][0]["child_frame_id"], "base_link");
  EXPECT_EQ(rosmsg::DecodeOdometry(m.at(kOdomChannel), rosmsg::Wire::kCdr).header.frame_id, "odom");
  const auto route = nlohmann::json::parse(m.at(kRouteChannel));
  EXPECT_EQ(route["poses"].size(), 2u);
}

TEST(LiveFeed, WithoutAnImageOnlyThePoseAndDecisionGoOn) {
  Feed feed({});
  FrameView f = AFrame(0);
  f.observation.image = cv::Mat();
  const auto m = ByChannel(feed.Messages(f));
  EXPECT_EQ(m.count(kCameraChannel), 0u);
  EXPECT_EQ(m.count(kDebugChannel), 0u);
  EXPECT_EQ(m.count(kRouteChannel), 0u);
  EXPECT_EQ(m.count(kDecisionChannel), 1u);
}

TEST(LiveFeed, ThePathIsThinnedAndBounded) {
  FeedOptions options;
  options.max_path_poses = 50;
  Feed feed({}, options);
  for (int i = 0; i < 400; ++i) {
    FrameView f = AFrame(i);
    f.observation.image = cv::Mat();
    f.observation.odometry = Pose2{0.001 * i, 0, 0};  // 1 mm a frame: one pose in 50
    (void)feed.Messages(f);
  }
  const auto latched = feed.Latched(0);
  ASSERT_EQ(latched.size(), 1u);
  const auto path = nlohmann::json::parse(latched[0].payload);
  EXPECT_GE(path["poses"].size(), 8u);
  EXPECT_LE(path["poses"].size(), 10u);
  Feed big({}, options);
  for (int i = 0; i < 1000; ++i) {
    FrameView f = AFrame(i);
    f.observation.image = cv::Mat();
    (void)big.Messages(f);
  }
  EXPECT_LE(nlohmann::json::parse(big.Latched(0)[0].payload)["poses"].size(), 51u);
}

TEST(LiveFeed, AStopIsADecisionAndAZeroCommand) {
  Feed feed({});
  FrameView f;
  f.method = "repeat";
  f.observation.t_ns = 5;
  f.stop_reason = "no camera frame for 0.5 s";
  const auto m = ByChannel(feed.Messages(f));
  const auto d = nlohmann::json::parse(m.at(kDecisionChannel));
  EXPECT_EQ(d["reason"], "no camera frame for 0.5 s");
  EXPECT_EQ(rosmsg::DecodeTwist(m.at(kCmdVelChannel), rosmsg::Wire::kCdr).v_mps, 0.0);
}

TEST(LiveFeed, TheBeliefIsAChannelOfTheFollowerOnly) {
  auto has = [](const std::vector<Channel>& cs, std::uint32_t id) {
    for (const Channel& c : cs)
      if (c.id == id) return true;
    return false;
  };
  EXPECT_TRUE(has(RunChannels("follow", false), kBeliefChannel));
  EXPECT_FALSE(has(RunChannels("repeat", true), kBeliefChannel));
  EXPECT_TRUE(has(RunChannels("repeat", true), kRouteChannel));
  EXPECT_FALSE(has(RunChannels("navigate", false), kRouteChannel));
  for (const Channel& c : RunChannels("follow", true)) {
    EXPECT_FALSE(c.schema.empty()) << c.topic;
    EXPECT_TRUE(c.schema_encoding == "ros2msg" || c.schema_encoding == "jsonschema") << c.topic;
    if (c.schema_encoding == "jsonschema") {
      EXPECT_TRUE(nlohmann::json::accept(c.schema)) << c.topic;
    }
  }
}

}  // namespace
}  // namespace mapless::live
