// The one face every navigation method shows a robot: a camera frame (and the wheel odometry, when
// there is one) in; a velocity command, a state and a reason out. The loop (loop.h) joins any
// method to any robot link (link.h) through this face, so a new method touches this module once.
//
// The three methods of mapless behind it (methods.h): the funnel-lane repeat (Kassir et al.), the
// visual-potential navigator (Ohnishi & Imiya) and the appearance route follower (Payá et al.).
#pragma once

#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <variant>

#include "mapless/core/pose.h"
#include "mapless/navigation/appearance.h"
#include "mapless/navigation/potential.h"
#include "mapless/navigation/repeat.h"

namespace mapless::robot {

// One camera frame as a method sees it: 8-bit grey at the method's image size, its capture time,
// and the wheel odometry at that time (REP-105 `odom` frame) when the robot has any.
struct Observation {
  cv::Mat image;  // CV_8UC1
  Timestamp t_ns = 0;
  std::optional<Pose2> odometry;
};

enum class MethodState {
  kDriving,  // the command moves the robot
  kStopped,  // the method holds the robot (waiting, searching, a camera fault): the reason says why
  kFinished,  // the method is done and succeeded (route completed, destination reached)
  kFailed,    // the method gave up (aborted): the reason says why
};
const char* MethodStateName(MethodState state);

// What the method decided on one frame. `detail` is the method's own step, for the status message
// and the debug image.
struct Decision {
  MethodState state = MethodState::kStopped;
  Twist2 command;      // zero unless kDriving
  std::string status;  // the method's own state name ("driving", "searching", "waiting", ...)
  std::string reason;  // why it stopped, finished or failed
  std::variant<std::monostate, navigation::RepeatStep, navigation::PotentialStep,
               navigation::FollowerStep>
      detail;
  bool done() const { return state == MethodState::kFinished || state == MethodState::kFailed; }
};

class Method {
 public:
  virtual ~Method() = default;
  virtual const char* name() const = 0;     // "repeat", "navigate", "follow"
  virtual bool needs_odometry() const = 0;  // refuses to drive on frames without odometry
  virtual cv::Size image_size() const = 0;  // the frame size the method works at (0x0: any)
  virtual Decision Step(const Observation& observation) = 0;
};

}  // namespace mapless::robot
