// TUM RGB-D trajectory format: one line per pose, "timestamp tx ty tz qx qy qz qw", timestamp in
// seconds. Planar poses are written with z = 0 and a rotation about z.
#pragma once

#include <string>
#include <vector>

#include "mapless/core/pose.h"

namespace mapless::io {

struct StampedPose {
  Timestamp t_ns = 0;
  Pose2 pose;
};

std::string FormatTum(const std::vector<StampedPose>& poses);
// Parses TUM text; throws InputError "NAME:LINE: ..." on a malformed line.
std::vector<StampedPose> ParseTum(const std::string& text, const std::string& name);
void WriteTumAtomic(const std::string& path, const std::vector<StampedPose>& poses);

}  // namespace mapless::io
