// A TUM trajectory as the odometry of a video's or an image folder's frames: `--poses FILE` beside
// an image folder (what `mapless sim drive` writes: frames/ and odometry.tum), so methods that need
// wheel odometry (the eigenspace teach) run on such folders as on a recording with an odometry
// topic.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "mapless/io/frame_source.h"
#include "mapless/io/tum.h"

namespace mapless::recording {

// Reads a TUM trajectory for use as odometry: at most io::kMaxTrajectoryBytes, finite values, at
// least one pose, times never going back. Throws InputError naming the file (and line or pose).
std::vector<io::StampedPose> ReadPoses(const std::string& path);

// A frame more than this after the trajectory's last pose carries no odometry (not a stale one).
inline constexpr double kPosesCoverS = 1.0;

// The poses as the frames' odometry. Frame times are shifted by the first pose's time (a folder's
// frames are index / fps from 0, a video's from its first frame), then each frame carries the
// newest pose not later than its time (1 ms of rounding allowed), as with an odometry topic.
std::unique_ptr<io::FrameSource> WithPoses(std::unique_ptr<io::FrameSource> source,
                                           std::vector<io::StampedPose> poses);

}  // namespace mapless::recording
