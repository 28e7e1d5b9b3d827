// Fixtures of the fleet's tests (fleet_test.cc, shared_views_test.cc): synthetic routes as a
// leader's records, directories and waiting.
#pragma once

#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <functional>
#include <map>
#include <string>
#include <thread>
#include <vector>

#include "mapless/core/rng.h"
#include "mapless/fleet/record.h"
#include "mapless/fleet/route_log.h"
#include "mapless/io/atomic_file.h"

namespace mapless::fleet::test {

namespace fs = std::filesystem;

inline std::string FreshDir(const std::string& name) {
  const std::string dir = ::testing::TempDir() + "mapless_fleet_" + name;
  fs::remove_all(dir);
  return dir;
}

inline route::Keyframe MakeKeyframe(int index) {
  Rng rng(static_cast<std::uint64_t>(index) + 1);
  route::Keyframe kf;
  kf.index = index;
  kf.t_ns = 100'000'000LL * (index + 1);
  kf.thumbnail = cv::Mat(60, 80, CV_8UC1, cv::Scalar(10 * index));
  for (int i = 0; i < 40; ++i)
    kf.keypoints.emplace_back(static_cast<float>(rng.Uniform(0, 320)),
                              static_cast<float>(rng.Uniform(0, 240)), 31.0f);
  kf.descriptors = cv::Mat(40, 32, CV_8UC1);
  for (int r = 0; r < 40; ++r)
    for (int c = 0; c < 32; ++c)
      kf.descriptors.at<std::uint8_t>(r, c) = static_cast<std::uint8_t>(rng.UniformInt(256));
  return kf;
}

inline route::StoredAppearanceImage MakeImage(int index) {
  Rng rng(static_cast<std::uint64_t>(index) + 7);
  route::StoredAppearanceImage image;
  image.low = cv::Mat(64, 64, CV_8UC1);
  for (int r = 0; r < 64; ++r)
    for (int c = 0; c < 64; ++c)
      image.low.at<std::uint8_t>(r, c) = static_cast<std::uint8_t>(rng.UniformInt(256));
  image.distance_m = 0.2 * index;
  image.odometry = Pose2{0.2 * index, 0.01 * index, 0.001 * index};
  return image;
}

// A funnel route of `keyframes` keyframes as a leader's records (sequence numbers set).
inline std::vector<Record> FunnelRecords(int keyframes, bool end) {
  RouteHeader h;
  h.kind = RouteKind::kFunnel;
  h.image_width = 320;
  h.image_height = 240;
  std::vector<Record> records = {HeaderRecord(h)};
  for (int i = 0; i < keyframes; ++i) records.push_back(KeyframeRecord(MakeKeyframe(i)));
  if (end) records.push_back(EndRecord());
  for (std::size_t i = 0; i < records.size(); ++i) records[i].sequence = i;
  return records;
}

inline std::vector<Record> ImageRecords(int images, bool end) {
  RouteHeader h;
  h.kind = RouteKind::kEigenspace;
  h.image_width = 320;
  h.image_height = 240;
  h.low_width = 64;
  h.low_height = 64;
  std::vector<Record> records = {HeaderRecord(h)};
  for (int i = 0; i < images; ++i) records.push_back(ImageRecord(MakeImage(i)));
  if (end) records.push_back(EndRecord());
  for (std::size_t i = 0; i < records.size(); ++i) records[i].sequence = i;
  return records;
}

// Every file of a directory, by relative path, with its bytes.
inline std::map<std::string, std::string> Files(const std::string& dir) {
  std::map<std::string, std::string> out;
  for (const auto& e : fs::recursive_directory_iterator(dir)) {
    if (!e.is_regular_file()) continue;
    out[fs::relative(e.path(), dir).string()] = io::ReadFile(e.path().string(), 1 << 26);
  }
  return out;
}

inline bool WaitFor(const std::function<bool()>& done, double seconds) {
  const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (std::chrono::steady_clock::now() < until) {
    if (done()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return done();
}

}  // namespace mapless::fleet::test
