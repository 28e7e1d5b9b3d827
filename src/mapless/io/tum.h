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

inline constexpr const char* kTumHeader = "# timestamp tx ty tz qx qy qz qw";
std::string FormatTum(const std::vector<StampedPose>& poses);
// One pose as a TUM line, without the newline (for journals written while recording).
std::string FormatTumLine(const StampedPose& pose);
// Timestamps beyond this many seconds (Unix time in the year 2255) do not fit in int64 nanoseconds.
inline constexpr double kMaxTumSeconds = 9e9;
// Parses TUM text; throws InputError "NAME:LINE: ..." on a malformed line, a number that is not
// finite or a timestamp beyond kMaxTumSeconds. A malformed last line without a newline is dropped
// instead: a record cut short when the recorder was killed.
std::vector<StampedPose> ParseTum(const std::string& text, const std::string& name);
void WriteTumAtomic(const std::string& path, const std::vector<StampedPose>& poses);

}  // namespace mapless::io
