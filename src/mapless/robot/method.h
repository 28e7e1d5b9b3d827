// The one face every navigation method shows a robot: a camera frame (and the wheel odometry, when
// there is one) in; a velocity command, a state and a reason out. The loop (loop.h) joins any
// method to any robot link (link.h) through this face, so a new method touches this module once.
//
// The three methods of mapless behind it (methods.h): the funnel-lane repeat (Kassir et al.), the
// visual-potential navigator (Ohnishi & Imiya) and the appearance route follower (Payá et al.).
#pragma once

#include <memory>
#include <nlohmann/json_fwd.hpp>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "mapless/core/pose.h"

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

// What a method shows of one decision, beyond the state, reason and command every method has: its
// own status fields and its drawing on the debug picture (status.h puts them together). Each
// method defines its own next to its Step (methods.h), so a new method adds its fields and picture
// without touching the status, the links or the recordings.
class DecisionDetail {
 public:
  virtual ~DecisionDetail() = default;
  // The method's fields of the status JSON ("destination", "matches", ...), added to `j`.
  virtual void Fields(nlohmann::json* j) const = 0;
  // Draws on `picture` (BGR: the frame, enlarged by `scale` when it was small) and adds short
  // text lines (at most 40 characters each, so they fit a 320-pixel picture) below the state line.
  virtual void Draw(cv::Mat* picture, double scale, std::vector<std::string>* lines) const = 0;
};

// What the method decided on one frame.
struct Decision {
  MethodState state = MethodState::kStopped;
  Twist2 command;        // zero unless kDriving
  std::string status;    // the method's own state name ("driving", "searching", "waiting", ...)
  std::string reason;    // why it stopped, finished or failed
  bool blocked = false;  // held by an obstacle on the way (kStopped), going on when it is gone
  std::shared_ptr<const DecisionDetail> detail;  // null: nothing beyond the above
  bool done() const { return state == MethodState::kFinished || state == MethodState::kFailed; }
  // The detail as the method's own type (null when it is another or none).
  template <typename T>
  const T* DetailAs() const {
    return dynamic_cast<const T*>(detail.get());
  }
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
