// The loop that joins any method (method.h) to any robot link (link.h): the eval suites, the live
// commands on a robot, `mapless sim serve` and replays all run through RunLoop.
//
// Per frame: take the next frame from the link; refuse it when it is stale (older than
// max_frame_age_s by the link's clock) or of the wrong size; let the method decide; clamp the
// command to the robot's limits; send it. The robot is stopped, and the status says why, when the
// method stops, finishes or fails, when frames stop arriving, on an emergency stop, when the link
// closes and when the caller interrupts the loop.
#pragma once

#include <functional>
#include <limits>
#include <string>

#include "mapless/robot/link.h"
#include "mapless/robot/method.h"

namespace mapless::robot {

struct LoopOptions {
  double max_speed_mps = std::numeric_limits<double>::infinity();        // |v| limit
  double max_turn_rate_radps = std::numeric_limits<double>::infinity();  // |omega| limit
  // A frame older than this (link clock minus frame stamp) is never acted on; 0: no check (the
  // simulator's frames are always fresh).
  double max_frame_age_s = 0.0;
  // No frame for this long (link clock, counted from the last frame): the run fails. 0: wait for
  // ever (the robot stays stopped).
  double give_up_without_frames_s = 0.0;
  // The method blocked by an obstacle (Decision::blocked) this long without a break (link clock):
  // the run fails with a reason that says what the user can do. 0: wait for ever (the suites: the
  // scenario decides when the way is free).
  double max_blocked_s = 0.0;
  void Validate() const;
};

struct LoopResult {
  bool finished = false;  // the method finished (kFinished)
  bool failed =
      false;           // the method failed, the link closed or gave up, or the loop was interrupted
  std::string reason;  // the last reason: why the loop ended
  int frames = 0;      // frames the method decided on
  int stale_frames = 0;  // frames refused as too old
};

// Called on every frame the method decided on, before the command is sent. Returning false ends
// the run there as finished (an evaluation's own goal, such as the end of a corridor, is reached);
// the robot is stopped.
using LoopObserver = std::function<bool(const Observation&, const Decision&)>;

// Runs until the method is done, the link closes, or `interrupted()` returns true (checked once per
// event; a SIGINT handler's flag, say).
LoopResult RunLoop(Method& method, RobotLink& link, const LoopOptions& options,
                   const LoopObserver& observer = {},
                   const std::function<bool()>& interrupted = {});

// The command limited to the options' speed and turn rate (each component clamped on its own, so a
// turn in place stays a turn in place).
Twist2 LimitCommand(const Twist2& command, const LoopOptions& options);

}  // namespace mapless::robot
