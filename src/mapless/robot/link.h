// The robot link: the one interface through which a method meets a robot. Timestamped camera
// frames and the wheel odometry come in; velocity commands and the per-frame decision go out; the
// robot can always be stopped. The simulator is one implementation (sim_link.h); the middleware
// adapters (src/mapless/ros1, ...) are others.
//
// Safety lives on both sides: a link reports when frames stop arriving (kNoFrame) or an emergency
// stop is pressed, and the loop (loop.h) then stops the robot and says why. Zero velocity is the
// default; a link sends a non-zero command only when the loop asks for it.
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "mapless/core/pose.h"
#include "mapless/robot/method.h"

namespace mapless::robot {

enum class LinkEventType {
  kFrame,    // a new camera frame (observation filled)
  kNoFrame,  // no frame within the link's camera timeout: the robot must stop
  kEStop,    // the emergency stop is engaged: the robot must stop
  kClosed,   // the link is gone (shutdown, end of a recording, the simulation ended): reason says
             // why
};

struct LinkEvent {
  LinkEventType type = LinkEventType::kClosed;
  Observation observation;
  std::string reason;
};

class RobotLink {
 public:
  virtual ~RobotLink() = default;
  // Waits for the next camera frame (the newest one; a link drops frames the method was too slow
  // for) or for a reason why there is none.
  virtual LinkEvent Next() = 0;
  // The command decided on the last frame, with the decision (status and debug outputs).
  virtual void Send(const Twist2& command, const Observation& observation,
                    const Decision& decision) = 0;
  // Zero velocity, and why (published as the status).
  virtual void Stop(const std::string& reason) = 0;
  // Why the run cannot go on after this frame (a collision in the simulator); empty while it may.
  virtual std::string Halted() { return {}; }
  // The link's clock: simulated time for the simulator and under ROS `use_sim_time`.
  virtual Timestamp now_ns() const = 0;
  // The robot's true pose now, where it is known (the simulator); recordings keep it.
  virtual std::optional<Pose2> GroundTruth() const { return std::nullopt; }
};

// A link put around another one for a run (a recording link, say); empty: none.
using LinkWrapper = std::function<std::unique_ptr<RobotLink>(RobotLink& inner)>;

}  // namespace mapless::robot
