#include "mapless/io/tum.h"

#include <cmath>
#include <cstdio>
#include <sstream>

#include "mapless/core/check.h"
#include "mapless/io/atomic_file.h"

namespace mapless::io {

std::string FormatTumLine(const StampedPose& p) {
  char line[256];
  const double half = 0.5 * p.pose.theta_rad;
  std::snprintf(line, sizeof(line), "%.6f %.6f %.6f 0 0 0 %.9f %.9f", ToSeconds(p.t_ns), p.pose.x_m,
                p.pose.y_m, std::sin(half), std::cos(half));
  return line;
}

std::string FormatTum(const std::vector<StampedPose>& poses) {
  std::string out = std::string(kTumHeader) + "\n";
  for (const auto& p : poses) out += FormatTumLine(p) + "\n";
  return out;
}

std::vector<StampedPose> ParseTum(const std::string& text, const std::string& name) {
  std::vector<StampedPose> out;
  std::istringstream in(text);
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    if (line.empty() || line[0] == '#') continue;
    std::istringstream fields(line);
    double t = 0, x = 0, y = 0, z = 0, qx = 0, qy = 0, qz = 0, qw = 0;
    if (!(fields >> t >> x >> y >> z >> qx >> qy >> qz >> qw)) {
      // A last line without its newline that does not parse is a record cut short by a killed
      // recorder (io/journal.h): everything before it is kept.
      if (in.eof() && !text.empty() && text.back() != '\n') break;
      throw InputError(name + ":" + std::to_string(line_no) + ": expected 8 numbers per line");
    }
    for (const double v : {t, x, y, z, qx, qy, qz, qw}) {
      if (!std::isfinite(v))
        throw InputError(name + ":" + std::to_string(line_no) + ": a number is not finite");
    }
    if (std::abs(t) > kMaxTumSeconds) {
      throw InputError(name + ":" + std::to_string(line_no) + ": timestamp " + std::to_string(t) +
                       " s is out of range");
    }
    out.push_back({FromSeconds(t), Pose2{x, y, 2.0 * std::atan2(qz, qw)}});
    out.back().pose.theta_rad = WrapAngle(out.back().pose.theta_rad);
  }
  return out;
}

void WriteTumAtomic(const std::string& path, const std::vector<StampedPose>& poses) {
  WriteFileAtomic(path, FormatTum(poses));
}

}  // namespace mapless::io
