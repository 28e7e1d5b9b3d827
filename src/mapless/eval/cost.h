// The cost figures of the evaluations on real images: wall-clock milliseconds of one item on one
// thread, and their median.
#pragma once

#include <algorithm>
#include <chrono>
#include <vector>

namespace mapless::eval {

// The evaluations on real images hold every image of a dataset while they run: at most this many
// pixels in all (512 megapixels of grey), refused before the work with the file it was reached at.
inline constexpr double kMaxHeldPixels = 512e6;

inline double MsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

inline double Median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::nth_element(v.begin(), v.begin() + static_cast<long>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

}  // namespace mapless::eval
