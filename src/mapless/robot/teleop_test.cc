#include "mapless/robot/teleop.h"

#include <gtest/gtest.h>

#include <deque>

#include "mapless/core/check.h"

namespace mapless::robot {
namespace {

TeleopOptions Limits() {
  TeleopOptions o;
  o.max_speed_mps = 0.4;
  o.max_turn_rate_radps = 1.0;
  o.speed_fraction = 0.5;
  o.hold_s = 0.6;
  return o;
}

TEST(TeleopKeys, AKeyDrivesWhileItRepeatsAndTheRobotStopsAfterItsRelease) {
  TeleopKeys keys(Limits());
  EXPECT_EQ(keys.Command(0.0).v_mps, 0.0);  // zero until a key is typed
  keys.Feed("w", 1.0);
  EXPECT_DOUBLE_EQ(keys.Command(1.0).v_mps, 0.2);
  EXPECT_DOUBLE_EQ(keys.Command(1.5).v_mps, 0.2);
  keys.Feed("w", 1.5);  // the key repeats
  EXPECT_DOUBLE_EQ(keys.Command(2.0).v_mps, 0.2);
  EXPECT_EQ(keys.Command(2.2).v_mps, 0.0);  // 0.7 s after the last repeat: released
  keys.Feed("a", 3.0);
  EXPECT_EQ(keys.Command(3.0).v_mps, 0.0);
  EXPECT_DOUBLE_EQ(keys.Command(3.0).omega_radps, 0.5);
  keys.Feed("e", 3.1);  // forward turning right
  EXPECT_DOUBLE_EQ(keys.Command(3.1).v_mps, 0.2);
  EXPECT_DOUBLE_EQ(keys.Command(3.1).omega_radps, -0.25);
  keys.Feed(" ", 3.2);  // space stops at once
  EXPECT_EQ(keys.Command(3.2).v_mps, 0.0);
  EXPECT_EQ(keys.Command(3.2).omega_radps, 0.0);
  keys.Feed("z", 3.3);  // an unknown key does nothing
  EXPECT_EQ(keys.Command(3.3).v_mps, 0.0);
  EXPECT_FALSE(keys.ended());
}

TEST(TeleopKeys, ArrowsEvenSplitAcrossReadsAndTheSpeedStaysWithinTheLimits) {
  TeleopKeys keys(Limits());
  keys.Feed("\x1b[", 0.0);
  EXPECT_EQ(keys.Command(0.0).v_mps, 0.0);
  keys.Feed("B", 0.1);  // Down: backward
  EXPECT_DOUBLE_EQ(keys.Command(0.1).v_mps, -0.2);
  keys.Feed("\x1bOD", 0.2);  // Left in application mode
  EXPECT_DOUBLE_EQ(keys.Command(0.2).omega_radps, 0.5);
  for (int i = 0; i < 20; ++i) keys.Feed("+", 0.3);
  EXPECT_DOUBLE_EQ(keys.speed_fraction(), 1.0);
  keys.Feed("\x1b[A", 0.4);  // Up at full speed: the robot's limit, not more
  EXPECT_DOUBLE_EQ(keys.Command(0.4).v_mps, 0.4);
  for (int i = 0; i < 20; ++i) keys.Feed("-", 0.5);
  EXPECT_NEAR(keys.speed_fraction(), 0.1, 1e-12);
  keys.Feed("\x04", 0.6);  // Ctrl-D ends, and the command is zero from then on
  EXPECT_TRUE(keys.ended());
  EXPECT_EQ(keys.Command(0.6).v_mps, 0.0);
}

TEST(TeleopKeys, BadOptionsAreRefusedByName) {
  TeleopOptions o = Limits();
  o.speed_fraction = 2.0;
  EXPECT_THROW(TeleopKeys{o}, InputError);
  o = Limits();
  o.hold_s = 0.0;
  EXPECT_THROW(TeleopKeys{o}, InputError);
}

TEST(TeleopMethod, DrivesOnKeysWaitsWithoutAndFinishesWhenTheInputEnds) {
  std::deque<KeyInput> inputs = {{"w", false}, {"", false}, {"", false}, {"", true}};
  double now = 0.0;
  TeleopMethod method(
      Limits(),
      [&] {
        KeyInput in = inputs.front();
        inputs.pop_front();
        return in;
      },
      [&] { return now; });
  Observation frame;
  Decision d = method.Step(frame);
  EXPECT_EQ(d.state, MethodState::kDriving);
  EXPECT_DOUBLE_EQ(d.command.v_mps, 0.2);
  now = 0.3;
  EXPECT_EQ(method.Step(frame).state, MethodState::kDriving);
  now = 1.0;
  d = method.Step(frame);
  EXPECT_EQ(d.state, MethodState::kStopped);
  EXPECT_EQ(d.command.v_mps, 0.0);
  EXPECT_EQ(d.reason, "no key held");
  d = method.Step(frame);
  EXPECT_EQ(d.state, MethodState::kFinished);
  EXPECT_EQ(d.reason, "the keyboard's input ended");
}

}  // namespace
}  // namespace mapless::robot
