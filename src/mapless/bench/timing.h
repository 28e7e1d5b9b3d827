// Timing helpers of `mapless bench` (stages.cc, teach_repeat.cc, fleet.cc).
#pragma once

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "mapless/sim/scenario.h"

namespace mapless::bench {

// `mapless bench --size WxH`: the frame size every stage runs at (default 320x240), each
// scenario's camera keeping its horizontal field of view. The JSON keys keep their "320x240".
inline cv::Size& BenchFrameSize() {
  static cv::Size size(320, 240);
  return size;
}

inline sim::Scenario BenchScenario(const std::string& name) {
  sim::Scenario s = sim::LoadScenario(name);
  const cv::Size size = BenchFrameSize();
  if (size.width != s.camera.model.width || size.height != s.camera.model.height) {
    const double hfov = 2.0 * std::atan(0.5 * s.camera.model.width / s.camera.model.fx);
    s.camera.model = sim::CameraModel::FromFov(size.width, size.height, hfov);
  }
  return s;
}

// Median over `repeats` calls of `fn(i)`, in milliseconds (after `warmup` untimed calls).
inline double MedianMs(int repeats, int warmup, const std::function<void(int)>& fn) {
  for (int i = 0; i < warmup; ++i) fn(i);
  std::vector<double> ms;
  ms.reserve(static_cast<std::size_t>(repeats));
  for (int i = 0; i < repeats; ++i) {
    const auto t0 = std::chrono::steady_clock::now();
    fn(i);
    const auto t1 = std::chrono::steady_clock::now();
    ms.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
  }
  std::nth_element(ms.begin(), ms.begin() + static_cast<long>(ms.size() / 2), ms.end());
  return ms[ms.size() / 2];
}

// Per-call times of `fn(i)` for i in [0, n), in milliseconds.
inline std::vector<double> TimesMs(int n, const std::function<void(int)>& fn) {
  std::vector<double> ms;
  for (int i = 0; i < n; ++i) {
    const auto t0 = std::chrono::steady_clock::now();
    fn(i);
    ms.push_back(
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
  }
  return ms;
}

// Median of `v` (the upper one of an even count); 0 when empty.
inline double Median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::nth_element(v.begin(), v.begin() + static_cast<long>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

}  // namespace mapless::bench
