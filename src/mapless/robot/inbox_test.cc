#include "mapless/robot/inbox.h"

#include <gtest/gtest.h>

#include <atomic>

#include "mapless/robot/sim_serve.h"

namespace mapless::robot {
namespace {

struct FakeClock {
  std::atomic<Timestamp> now{0};
  InboxClock clock() {
    return {[this] { return now.load(); }, [] { return true; }, [] { return true; }};
  }
};

RobotFile Robot() {
  RobotFile r;
  r.topics.odometry = "";
  r.give_up_without_frames_s = 0;
  r.connect_timeout_s = 0.5;
  return r;
}

TEST(FrameInbox, HandsOverTheNewestFrameAndDropsACopyOfIt) {
  FakeClock clock;
  FrameInbox inbox(Robot(), {}, "/camera", {}, clock.clock());
  inbox.Start();
  const cv::Mat a(24, 32, CV_8UC1, cv::Scalar(10)), b(24, 32, CV_8UC1, cv::Scalar(20));
  inbox.Deliver(a, 100, 0);
  inbox.Deliver(b, 200, 0);  // newer: replaces a
  LinkEvent e = inbox.Next();
  ASSERT_EQ(e.type, LinkEventType::kFrame);
  EXPECT_EQ(e.observation.t_ns, 200);
  EXPECT_EQ(e.observation.image.at<std::uint8_t>(0, 0), 20);
  // The same frame again (a lockstep simulator's resend): no new frame, the watchdog fires.
  inbox.Deliver(b, 200, 0);
  clock.now = 200 + FromSeconds(0.25);
  e = inbox.Next();
  EXPECT_EQ(e.type, LinkEventType::kNoFrame);
  EXPECT_NE(e.reason.find("no camera frame on /camera"), std::string::npos) << e.reason;
}

TEST(FrameInbox, EStopWinsOverFramesUntilReleased) {
  FakeClock clock;
  FrameInbox inbox(Robot(), {}, "/camera", {}, clock.clock());
  inbox.Start();
  inbox.Deliver(cv::Mat(24, 32, CV_8UC1, cv::Scalar(1)), 5, 0);
  inbox.SetEStop(true, "/mapless/estop");
  LinkEvent e = inbox.Next();
  EXPECT_EQ(e.type, LinkEventType::kEStop);
  EXPECT_NE(e.reason.find("/mapless/estop"), std::string::npos);
  inbox.SetEStop(false, "/mapless/estop");
  EXPECT_EQ(inbox.Next().type, LinkEventType::kFrame);
}

TEST(FrameInbox, BadInputIsSaidOnceAndNamedInTheStop) {
  FakeClock clock;
  int said = 0;
  FrameInbox inbox(
      Robot(), {}, "/camera", [&](const std::string&) { ++said; }, clock.clock());
  inbox.Start();
  inbox.Warn("image:yuv422", "/camera: encoding 'yuv422' is not supported");
  inbox.Warn("image:yuv422", "/camera: encoding 'yuv422' is not supported");
  EXPECT_EQ(said, 1);
  clock.now = FromSeconds(1.0);  // past connect_timeout_s before any frame
  const LinkEvent e = inbox.Next();
  EXPECT_EQ(e.type, LinkEventType::kNoFrame);
  EXPECT_NE(e.reason.find("yuv422"), std::string::npos) << e.reason;
}

TEST(EncodeCamera, GivesTheMessagesOfEachEncoding) {
  const cv::Mat grey(24, 32, CV_8UC1, cv::Scalar(7));
  const CameraMessage mono = EncodeCamera(grey, "mono8", {});
  EXPECT_FALSE(mono.compressed);
  EXPECT_EQ(mono.step, 32u);
  EXPECT_EQ(mono.data.size(), 32u * 24u);
  const CameraMessage rgb = EncodeCamera(grey, "rgb8", cv::Size(64, 48));
  EXPECT_EQ(rgb.width, 64u);
  EXPECT_EQ(rgb.step, 64u * 3u);
  EXPECT_EQ(rgb.data.size(), 64u * 48u * 3u);
  const CameraMessage png = EncodeCamera(grey, "png", {});
  EXPECT_TRUE(png.compressed);
  ASSERT_GE(png.data.size(), 8u);
  EXPECT_EQ(png.data[1], 'P');
}

}  // namespace
}  // namespace mapless::robot
