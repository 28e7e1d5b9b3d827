// The run layer is open to new methods and new links: a method and a link written here, each
// registered in one line, run through the same code as the commands (run::LinkKinds,
// run::RunMethod), with the loop's safety rules, the decision log and the method's own status
// fields.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>

#include "mapless/core/check.h"
#include "mapless/robot/status.h"
#include "mapless/run/link_kinds.h"
#include "mapless/run/run_method.h"
#include "mapless/run/status_line.h"
#include "mapless/run/text.h"

namespace mapless::run {
namespace {

// A method that drives straight on until it has seen `frames` frames, then finishes.
struct StraightDetail : robot::DecisionDetail {
  int left = 0;
  void Fields(nlohmann::json* j) const override { (*j)["frames_left"] = left; }
  void Draw(cv::Mat* picture, double, std::vector<std::string>* lines) const override {
    cv::line(*picture, {0, 0}, {10, 10}, cv::Scalar(0, 0, 255));
    lines->push_back("left " + std::to_string(left));
  }
};

class StraightMethod : public robot::Method {
 public:
  explicit StraightMethod(int frames) : left_(frames) {}
  const char* name() const override { return "straight"; }
  bool needs_odometry() const override { return false; }
  cv::Size image_size() const override { return {32, 24}; }
  robot::Decision Step(const robot::Observation&) override {
    robot::Decision d;
    auto detail = std::make_shared<StraightDetail>();
    detail->left = --left_;
    d.detail = detail;
    if (left_ <= 0) {
      d.state = robot::MethodState::kFinished;
      d.status = "done";
      d.reason = "told to stop";
      return d;
    }
    d.state = robot::MethodState::kDriving;
    d.status = "driving";
    d.command = Twist2{0.5, 0.0};
    return d;
  }

 private:
  int left_;
};

// A link that replays a list of frames and keeps what it was told.
class ListLink : public robot::RobotLink {
 public:
  explicit ListLink(int frames, cv::Size size = {32, 24}) : frames_(frames), size_(size) {}
  robot::LinkEvent Next() override {
    robot::LinkEvent e;
    if (next_ >= frames_) {
      e.type = robot::LinkEventType::kClosed;
      e.reason = "end of the list";
      return e;
    }
    e.type = robot::LinkEventType::kFrame;
    e.observation.image = cv::Mat(size_, CV_8UC1, cv::Scalar(next_));
    e.observation.t_ns = FromSeconds(0.1 * next_);
    now_ = e.observation.t_ns;
    ++next_;
    return e;
  }
  void Send(const Twist2& c, const robot::Observation&, const robot::Decision&) override {
    sent.push_back(c);
  }
  void Stop(const std::string& reason) override { stops.push_back(reason); }
  Timestamp now_ns() const override { return now_; }
  std::vector<Twist2> sent;
  std::vector<std::string> stops;

 private:
  int frames_;
  cv::Size size_;
  int next_ = 0;
  Timestamp now_ = 0;
};

LinkKinds KindsWithList(ListLink** opened) {
  LinkKinds kinds;
  // The one registration line of the new link.
  kinds.Add({"list", "list:N", [](const std::string& t) { return t.rfind("list:", 0) == 0; },
             [opened](const std::string& t, const LinkRequest&) {
               auto link = std::make_unique<ListLink>(std::stoi(t.substr(5)));
               *opened = link.get();
               return std::unique_ptr<robot::RobotLink>(std::move(link));
             }});
  return kinds;
}

TEST(RunLayer, ANewMethodOnANewLinkRunsThroughTheLoopWithItsOwnFields) {
  ListLink* list = nullptr;
  const LinkKinds kinds = KindsWithList(&list);
  std::unique_ptr<robot::RobotLink> link = kinds.Open("list:10", LinkRequest{});
  ASSERT_NE(list, nullptr);
  StraightMethod method(5);
  std::vector<nlohmann::json> log;
  std::vector<std::string> said;
  RunOptions options;
  options.loop.max_speed_mps = 0.2;  // the loop's limits apply to any method
  options.log = [&](const nlohmann::json& j) { log.push_back(j); };
  options.say = [&](const std::string& s) { said.push_back(s); };
  options.interrupted = [] { return false; };
  const RunOutcome outcome = RunMethod(method, *link, options);
  EXPECT_TRUE(outcome.loop.finished);
  EXPECT_EQ(outcome.loop.reason, "told to stop");
  EXPECT_EQ(outcome.loop.frames, 5);
  EXPECT_EQ(outcome.driving_frames, 4);
  ASSERT_EQ(log.size(), 5U);
  EXPECT_EQ(log[0]["method"], "straight");
  EXPECT_EQ(log[0]["frames_left"], 4);  // the method's own field, from its detail
  EXPECT_EQ(log[4]["state"], "finished");
  ASSERT_EQ(list->sent.size(), 5U);  // 4 commands and the final zero
  EXPECT_DOUBLE_EQ(list->sent[0].v_mps, 0.2);
  EXPECT_DOUBLE_EQ(list->sent[4].v_mps, 0.0);
  ASSERT_FALSE(list->stops.empty());  // stopped at the end, with the reason
  EXPECT_EQ(list->stops.back(), "told to stop");
  ASSERT_EQ(said.size(), 1U);
  EXPECT_EQ(said[0], "straight: done: told to stop");
}

TEST(RunLayer, TheLinkClosingStopsTheRobotAndTheRunSaysWhy) {
  ListLink link(3);
  StraightMethod method(100);
  RunOptions options;
  options.interrupted = [] { return false; };
  const RunOutcome outcome = RunMethod(method, link, options);
  EXPECT_FALSE(outcome.loop.finished);
  EXPECT_EQ(outcome.loop.reason, "end of the list");
  EXPECT_EQ(link.stops.back(), "end of the list");
}

TEST(RunLayer, FramesOfTheWrongSizeEndTheRunWithoutDriving) {
  ListLink link(3, {64, 48});
  StraightMethod method(100);
  RunOptions options;
  options.interrupted = [] { return false; };
  const RunOutcome outcome = RunMethod(method, link, options);
  EXPECT_FALSE(outcome.loop.finished);
  EXPECT_NE(outcome.loop.reason.find("needs 8-bit grey 32x24"), std::string::npos);
  EXPECT_TRUE(link.sent.empty());
}

TEST(RunLayer, AnInterruptStopsTheRun) {
  ListLink link(100);
  StraightMethod method(100);
  RunOptions options;
  int frames = 0;
  options.observer = [&](const robot::Observation&, const robot::Decision&) {
    ++frames;
    return true;
  };
  options.interrupted = [&] { return frames >= 3; };
  const RunOutcome outcome = RunMethod(method, link, options);
  EXPECT_TRUE(outcome.interrupted);
  EXPECT_EQ(outcome.loop.reason, "interrupted");
  EXPECT_EQ(link.stops.back(), "interrupted");
}

TEST(RunLayer, TheMethodDrawsItsOwnDebugPicture) {
  robot::Observation obs;
  obs.image = cv::Mat(24, 32, CV_8UC1, cv::Scalar(0));
  StraightMethod method(3);
  const robot::Decision d = method.Step(obs);
  const cv::Mat picture = robot::DebugImage(obs, d);
  EXPECT_EQ(picture.cols, 320);  // small frames are enlarged
  EXPECT_GT(cv::countNonZero(picture.reshape(1)), 0);
}

// A method held by an obstacle that never goes: the run ends after max_blocked_s (issue 42: a
// blocked repeat waited until Ctrl-C), with a reason that says what to do; a break restarts the
// count.
class BlockedMethod : public robot::Method {
 public:
  explicit BlockedMethod(int free_at) : free_at_(free_at) {}
  const char* name() const override { return "blocked"; }
  bool needs_odometry() const override { return false; }
  cv::Size image_size() const override { return {}; }
  robot::Decision Step(const robot::Observation&) override {
    robot::Decision d;
    d.state = robot::MethodState::kStopped;
    d.status = "blocked";
    d.reason = "obstacle ahead";
    d.blocked = ++frames_ != free_at_;
    return d;
  }

 private:
  int free_at_;
  int frames_ = 0;
};

TEST(RunLayer, ABlockedRobotStopsWaitingAfterMaxBlocked) {
  ListLink link(100);       // 10 frames a second
  BlockedMethod method(5);  // one frame free at 0.4 s: the count starts again at 0.5 s
  RunOptions options;
  options.loop.max_blocked_s = 1.0;
  options.interrupted = [] { return false; };
  const RunOutcome outcome = RunMethod(method, link, options);
  EXPECT_FALSE(outcome.loop.finished);
  EXPECT_EQ(outcome.loop.frames, 17);  // blocked from 0.5 s, more than 1 s at 1.6 s
  EXPECT_EQ(outcome.loop.reason.rfind("blocked for 1.10 s (obstacle ahead): clear the way", 0), 0u)
      << outcome.loop.reason;
  for (const Twist2& c : link.sent) EXPECT_EQ(c.v_mps, 0.0);
  ListLink forever(100);
  BlockedMethod again(-1);
  options.loop.max_blocked_s = 0.0;  // wait for ever: the link's end ends it
  EXPECT_EQ(RunMethod(again, forever, options).loop.reason, "end of the list");
}

// The debug picture's text stays within the picture (a 320-pixel picture cut the reason off).
TEST(RunLayer, TheDebugPicturesTextFitsItsWidth) {
  const std::string reason =
      "blocked: obstacle ahead (34% of the ground ahead does not move like the ground): stopped, "
      "waiting for the way to be free";
  const auto width = [](const std::string& line) {
    int baseline = 0;
    return cv::getTextSize(line, cv::FONT_HERSHEY_PLAIN, 0.9, 1, &baseline).width;
  };
  ASSERT_GT(width(reason), 312);
  const std::vector<std::string> lines = robot::WrapText(reason, 312, 4);
  ASSERT_GE(lines.size(), 2u);
  std::string joined;
  for (const std::string& line : lines) {
    EXPECT_LE(width(line), 312) << line;
    joined += (joined.empty() ? "" : " ") + line;
  }
  EXPECT_EQ(joined, reason);  // every word, in order
  const std::vector<std::string> two = robot::WrapText(reason, 312, 2);
  ASSERT_EQ(two.size(), 2u);
  EXPECT_EQ(two[1].substr(two[1].size() - 3), "...");
  EXPECT_LE(width(two[1]), 312);
  robot::Observation obs;
  obs.image = cv::Mat(240, 320, CV_8UC1, cv::Scalar(128));
  robot::Decision d;
  d.reason = reason;
  EXPECT_EQ(robot::DebugImage(obs, d).cols, 320);
}

TEST(LinkKinds, StandardKindsTellSourcesApartAndRefuseWhatTheyCannotOpen) {
  const robot::MiddlewareRegistry none;
  LinkKinds kinds = StandardLinkKinds(none);
  EXPECT_EQ(kinds.For("robot.yaml").name, "robot");
  EXPECT_EQ(kinds.For("camera:0").name, "camera");
  EXPECT_EQ(kinds.For("run.mcap").name, "recording");
  EXPECT_EQ(kinds.Find("sim:office"), nullptr);  // the simulator is its own source
  EXPECT_THROW(kinds.For("sim:office"), InputError);
  EXPECT_THROW(kinds.Add({"robot", "again", [](const std::string&) { return true; },
                          [](const std::string&, const LinkRequest&) {
                            return std::unique_ptr<robot::RobotLink>();
                          }}),
               std::logic_error);
}

}  // namespace
}  // namespace mapless::run

namespace mapless::run {
namespace {

TEST(Text, WrapWordsKeepsLinesWithinTheWidth) {
  const std::vector<std::string> lines =
      WrapWords("the quick brown fox jumps over the lazy dog\nnext paragraph", 12);
  const std::vector<std::string> want = {"the quick",    "brown fox", "jumps over",
                                         "the lazy dog", "next",      "paragraph"};
  EXPECT_EQ(lines, want);
  EXPECT_EQ(WrapWords("averyveryverylongword x", 5),
            (std::vector<std::string>{"averyveryverylongword", "x"}));
  EXPECT_EQ(WrapWords("", 10), (std::vector<std::string>{""}));
}

TEST(StatusLine, SaysStateWhereAndWhatItSeesWithinTheWidth) {
  nlohmann::json s = {{"method", "repeat"},  {"state", "driving"}, {"status", "driving"},
                      {"destination", 12},   {"matches", 85},      {"v_mps", 0.2},
                      {"omega_radps", 0.05}, {"t_s", 11.3}};
  EXPECT_EQ(StatusLineText(s, 3.42, 11.3),
            "repeat: driving | keyframe 12 | 85 matches | 0.20 m/s 0.05 rad/s | 3.4 m | 11.3 s");
  s["state"] = "stopped";
  s["status"] = "blocked";
  s["reason"] = "obstacle ahead (34% of the ground ahead): stopped, waiting for the way to be free";
  const std::string line = StatusLineText(s, 3.42, 11.3);
  EXPECT_EQ(line.rfind("repeat: stopped (blocked) | keyframe 12", 0), 0u) << line;
  EXPECT_LE(line.size(), 99u);
  EXPECT_EQ(line.substr(line.size() - 3), "...");
  // The distance is the commanded speed over the time between decisions.
  StatusLine quiet(false);
  quiet.Show({{"t_s", 0.0}, {"v_mps", 0.5}});
  quiet.Show({{"t_s", 2.0}, {"v_mps", 0.5}});
  quiet.Show({{"t_s", 3.0}, {"v_mps", -0.5}});  // backwards counts too
  EXPECT_FALSE(quiet.enabled());
  EXPECT_DOUBLE_EQ(quiet.driven_m(), 1.5);
}

}  // namespace
}  // namespace mapless::run
