// Camera faults, checked on every frame before any method looks at it: a dropped frame (empty
// image), a black frame, an over-exposed frame, a featureless view (a blank wall, a lens cap
// letting light through) and a frozen camera (a driver re-delivering its last buffer). Each
// navigator (repeat, potential, appearance follower) stops the robot on the frame where the fault
// shows, says which fault, and carries on from where it was once the images are usable again.
//
// Frozen: real sensors never give two bit-identical frames while the robot moves (noise alone
// changes them), so a frame identical to the previous one while the robot was commanded to move is
// a frozen source. The fault then holds until the image changes. A stopped robot may legitimately
// see the same image (the simulator has no sensor noise by default), so identical frames while
// stopped are not a fault. Nor are they on the first frame after the robot is told to move: it
// may not have started yet (the command arrived after the frame was taken, latency, a loaded
// computer); the command of the frame before must also have been a move.
#pragma once

#include <opencv2/core.hpp>
#include <string>

#include "mapless/core/pose.h"

namespace mapless::navigation {

struct CameraCheckOptions {
  double black_mean = 8.0;              // mean grey level at or below this: black frame
  double saturated_level = 250.0;       // a pixel at or above this is saturated ...
  double max_saturated_fraction = 0.7;  // ... and more than this fraction of them: over-exposed
  double min_stddev = 2.0;              // grey-level standard deviation below this: featureless
  double moving_speed_mps = 0.02;       // commanded faster than this (or turning faster than
  double moving_rate_radps = 0.05;      // this) counts as moving, for the frozen check
  void Validate() const;
};

enum class CameraFault { kNone, kNoImage, kBlack, kOverExposed, kFeatureless, kFrozen };
const char* CameraFaultName(CameraFault f);  // "none", "no image", "black frame", ...

struct CameraCheck {
  CameraFault fault = CameraFault::kNone;
  std::string reason;  // e.g. "camera fault: black frame (mean grey level 0.0)"; empty when usable
  bool usable() const { return fault == CameraFault::kNone; }
};

class CameraMonitor {
 public:
  explicit CameraMonitor(CameraCheckOptions options = {});
  // Checks one frame. `last_command` is what the robot was told to do since the previous frame.
  CameraCheck Check(const cv::Mat& image, const Twist2& last_command);

 private:
  CameraCheckOptions options_;
  cv::Mat previous_;         // the last frame that was checked (for the frozen test)
  bool frozen_ = false;      // latched until the image changes
  bool was_moving_ = false;  // the command before `last_command` was a move
};

}  // namespace mapless::navigation
