#include "mapless/robot/inbox.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <thread>

#include "mapless/core/interrupt.h"
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
  // The frame from before the e-stop was answered with it; the next one is acted on.
  inbox.Deliver(cv::Mat(24, 32, CV_8UC1, cv::Scalar(2)), 10, 0);
  e = inbox.Next();
  ASSERT_EQ(e.type, LinkEventType::kFrame);
  EXPECT_EQ(e.observation.t_ns, 10);
}

// Issue 40: during an e-stop the loop turned as fast as it could, publishing tens of thousands of
// zero Twists a second. Now the stop is said once per frame, or once per camera_timeout_s.
TEST(FrameInbox, EStopIsSaidAtMostOncePerFrameOrWatchdogPeriod) {
  FakeClock clock;
  RobotFile robot = Robot();
  robot.camera_timeout_s = 0.1;
  FrameInbox inbox(robot, {}, "/camera", {}, clock.clock());
  inbox.Start();
  inbox.SetEStop(true, "/estop");
  std::atomic<bool> done{false};
  std::thread camera([&] {  // 20 frames at 50 Hz
    for (int i = 1; i <= 20; ++i) {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
      inbox.Deliver(cv::Mat(24, 32, CV_8UC1, cv::Scalar(i)), i * 20'000'000, 0);
    }
    done = true;
  });
  int stops = 0;
  const std::int64_t start = SteadyNs();
  while (!done) {
    EXPECT_EQ(inbox.Next().type, LinkEventType::kEStop);
    ++stops;
  }
  camera.join();
  const double seconds = ToSeconds(SteadyNs() - start);
  // One at engagement, one per frame (20), and watchdog repeats only where frames were late.
  EXPECT_GE(stops, 10);
  EXPECT_LE(stops, 1 + 20 + static_cast<int>(seconds / 0.1) + 1) << seconds << " s";
  // Without frames: about one per camera_timeout_s.
  const std::int64_t quiet = SteadyNs();
  int quiet_stops = 0;
  while (ToSeconds(SteadyNs() - quiet) < 0.35) {
    EXPECT_EQ(inbox.Next().type, LinkEventType::kEStop);
    ++quiet_stops;
  }
  EXPECT_GE(quiet_stops, 2);
  EXPECT_LE(quiet_stops, 5);
}

TEST(FrameInbox, AnInterruptEndsTheWaitEvenWhenTheClockStopped) {
  FakeClock clock;  // never advances: a simulated clock that stopped
  RobotFile robot = Robot();
  robot.give_up_without_frames_s = 30;
  FrameInbox inbox(robot, {}, "/camera", {}, clock.clock());
  inbox.Start();
  std::thread ctrl_c([] {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    RequestInterrupt();
  });
  const std::int64_t start = SteadyNs();
  const LinkEvent e = inbox.Next();
  ctrl_c.join();
  ClearInterrupt();
  EXPECT_EQ(e.type, LinkEventType::kClosed);
  EXPECT_EQ(e.reason, "interrupted");
  EXPECT_LT(ToSeconds(SteadyNs() - start), 5.0);
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
