// What the evaluations on real images share: the file names of a folder's images, the bound on
// the pixels they hold, and the cost figures (wall-clock milliseconds of one item on one thread,
// and their median).
#pragma once

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <string>
#include <vector>

#include "mapless/core/check.h"
#include "mapless/io/frame_source.h"

namespace mapless::eval {

// The evaluations on real images hold every image of a dataset while they run: at most this many
// pixels in all (512 megapixels of grey), refused before the work with the file it was reached at.
inline constexpr double kMaxHeldPixels = 512e6;

// The file names (not paths) of a folder's images in file-name order (io::ImageFilesIn); throws
// InputError naming `option` and the folder when it is not one.
inline std::vector<std::string> ImageNamesIn(const std::string& dir, const std::string& option) {
  MAPLESS_CHECK(std::filesystem::is_directory(dir),
                option << " " << dir << ": not a folder of images");
  std::vector<std::string> names;
  for (const std::string& path : io::ImageFilesIn(dir))
    names.push_back(std::filesystem::path(path).filename().string());
  return names;
}

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
