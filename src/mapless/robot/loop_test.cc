#include "mapless/robot/loop.h"

#include <gtest/gtest.h>

#include <deque>

#include "mapless/robot/methods.h"
#include "mapless/robot/sim_link.h"
#include "mapless/sim/scenario.h"

namespace mapless::robot {
namespace {

// A link that plays a script of events and records what the loop sent.
class ScriptLink : public RobotLink {
 public:
  std::deque<LinkEvent> events;
  std::vector<Twist2> sent;
  std::vector<std::string> stops;
  Timestamp clock_ns = 0;

  LinkEvent Next() override {
    if (events.empty()) return LinkEvent{LinkEventType::kClosed, {}, "script ended"};
    LinkEvent e = events.front();
    events.pop_front();
    if (e.type == LinkEventType::kFrame) clock_ns = std::max(clock_ns, e.observation.t_ns);
    return e;
  }
  void Send(const Twist2& c, const Observation&, const Decision&) override { sent.push_back(c); }
  void Stop(const std::string& reason) override { stops.push_back(reason); }
  Timestamp now_ns() const override { return clock_ns; }
};

// Drives at a fixed command; finishes after `finish_after` frames.
class FixedMethod : public Method {
 public:
  Twist2 command{1.0, -3.0};
  int finish_after = 1000;
  int steps = 0;
  const char* name() const override { return "fixed"; }
  bool needs_odometry() const override { return false; }
  cv::Size image_size() const override { return {32, 24}; }
  Decision Step(const Observation&) override {
    Decision d;
    d.state = ++steps >= finish_after ? MethodState::kFinished : MethodState::kDriving;
    d.command = command;
    d.status = "driving";
    d.reason = d.state == MethodState::kFinished ? "done" : "";
    return d;
  }
};

LinkEvent Frame(double t_s, int w = 32, int h = 24) {
  LinkEvent e;
  e.type = LinkEventType::kFrame;
  e.observation.image = cv::Mat(h, w, CV_8UC1, cv::Scalar(100));
  e.observation.t_ns = FromSeconds(t_s);
  return e;
}

TEST(RunLoop, SendsLimitedCommandsAndStopsWhenTheMethodFinishes) {
  ScriptLink link;
  for (int i = 0; i < 5; ++i) link.events.push_back(Frame(0.1 * i));
  FixedMethod method;
  method.finish_after = 3;
  LoopOptions options;
  options.max_speed_mps = 0.3;
  options.max_turn_rate_radps = 1.0;
  const LoopResult result = RunLoop(method, link, options);
  EXPECT_TRUE(result.finished);
  EXPECT_EQ(result.frames, 3);
  ASSERT_EQ(link.sent.size(), 3u);  // the last decision is sent with a zero command
  EXPECT_EQ(link.sent[2].v_mps, 0.0);
  EXPECT_DOUBLE_EQ(link.sent[0].v_mps, 0.3);
  EXPECT_DOUBLE_EQ(link.sent[0].omega_radps, -1.0);
  ASSERT_EQ(link.stops.size(), 1u);
  EXPECT_EQ(link.stops[0], "done");
}

TEST(RunLoop, NeverActsOnAStaleFrame) {
  ScriptLink link;
  link.events.push_back(Frame(1.0));
  link.clock_ns = FromSeconds(5.0);  // the frame arrives 4 s late
  link.events.push_back(Frame(5.0));
  FixedMethod method;
  LoopOptions options;
  options.max_frame_age_s = 0.5;
  const LoopResult result = RunLoop(method, link, options);
  EXPECT_EQ(result.stale_frames, 1);
  EXPECT_EQ(method.steps, 1);
  ASSERT_GE(link.stops.size(), 1u);
  EXPECT_NE(link.stops[0].find("stale frame"), std::string::npos) << link.stops[0];
  EXPECT_FALSE(result.finished);
  EXPECT_EQ(result.reason, "script ended");
}

TEST(RunLoop, StopsWithoutFramesAndOnEStopAndGivesUp) {
  ScriptLink link;
  link.events.push_back(Frame(0.0));
  link.events.push_back({LinkEventType::kEStop, {}, ""});
  link.events.push_back({LinkEventType::kNoFrame, {}, "no camera frame for 0.20 s"});
  FixedMethod method;
  LoopOptions options;
  options.give_up_without_frames_s = 1.0;
  RunLoop(method, link, options);
  ASSERT_EQ(link.stops.size(), 3u);
  EXPECT_EQ(link.stops[0], "emergency stop");
  EXPECT_EQ(link.stops[1], "no camera frame for 0.20 s");
  EXPECT_EQ(method.steps, 1);  // neither event reached the method

  // The clock runs on while no frame comes: past give_up_without_frames_s the run fails.
  ScriptLink late;
  late.events.push_back(Frame(0.0));
  late.events.push_back({LinkEventType::kNoFrame, {}, "no camera frame"});
  late.events.push_back({LinkEventType::kNoFrame, {}, "no camera frame"});
  FixedMethod m2;
  int polls = 0;
  const LoopResult r2 = RunLoop(m2, late, options, {}, [&] {
    if (++polls > 3) late.clock_ns = FromSeconds(2.0);
    return false;
  });
  EXPECT_TRUE(r2.failed);
  EXPECT_NE(r2.reason.find("giving up"), std::string::npos) << r2.reason;
}

TEST(RunLoop, RefusesAFrameOfAnotherSizeAndHonoursAnInterrupt) {
  ScriptLink link;
  link.events.push_back(Frame(0.0, 64, 48));
  FixedMethod method;
  const LoopResult result = RunLoop(method, link, LoopOptions{});
  EXPECT_TRUE(result.failed);
  EXPECT_NE(result.reason.find("64x48"), std::string::npos) << result.reason;
  EXPECT_EQ(method.steps, 0);

  ScriptLink link2;
  link2.events.push_back(Frame(0.0));
  const LoopResult r2 = RunLoop(method, link2, LoopOptions{}, {}, [] { return true; });
  EXPECT_EQ(r2.reason, "interrupted");
  ASSERT_EQ(link2.stops.size(), 1u);
}

TEST(LimitCommand, ClampsEachComponentAndZeroesNonFinite) {
  LoopOptions o;
  o.max_speed_mps = 0.5;
  o.max_turn_rate_radps = 0.2;
  const Twist2 a = LimitCommand({-2.0, 0.1}, o);
  EXPECT_DOUBLE_EQ(a.v_mps, -0.5);
  EXPECT_DOUBLE_EQ(a.omega_radps, 0.1);
  const Twist2 b = LimitCommand({std::nan(""), 0.1}, o);
  EXPECT_EQ(b.v_mps, 0.0);
  EXPECT_EQ(b.omega_radps, 0.0);
}

TEST(SimLink, IsDeterministicAndStepsInLockstep) {
  const sim::Scenario scenario = sim::LoadScenario("table1_almost_straight");
  auto run = [&] {
    sim::Simulation sim(scenario.world, scenario.camera, {}, 7);
    const int r = sim.AddRobot(scenario.teach_start, scenario.robot);
    SimLink link(sim, r, SimLinkOptions{});
    FixedMethod method;
    method.command = {0.2, 0.1};
    method.finish_after = 5;
    struct Sized : FixedMethod {
      cv::Size image_size() const override { return {}; }
    } sized;
    sized.command = method.command;
    sized.finish_after = 5;
    std::vector<Timestamp> stamps;
    RunLoop(sized, link, LoopOptions{}, [&](const Observation& o, const Decision&) {
      stamps.push_back(o.t_ns);
      EXPECT_TRUE(o.odometry.has_value());
      return true;
    });
    EXPECT_EQ(stamps.size(), 5u);
    EXPECT_EQ(stamps[1] - stamps[0], FromSeconds(0.1));
    return link.truth();
  };
  const Pose2 a = run();
  const Pose2 b = run();
  EXPECT_EQ(a.x_m, b.x_m);
  EXPECT_EQ(a.theta_rad, b.theta_rad);
  EXPECT_GT(a.DistanceTo(scenario.teach_start), 0.05);
}

}  // namespace
}  // namespace mapless::robot
