// Helpers for the project's tests (header-only; not used by library code).
#pragma once

#include <cstring>
#include <functional>
#include <opencv2/core.hpp>
#include <string>

#include "mapless/core/check.h"

namespace mapless::testing {

// The message of the InputError that `f` throws, or "" when it throws none.
inline std::string InputErrorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

// The same size, type and bytes (not only equal values: a -0 for a +0 would count).
inline bool SameBytes(const cv::Mat& a, const cv::Mat& b) {
  if (a.size() != b.size() || a.type() != b.type()) return false;
  for (int y = 0; y < a.rows; ++y) {
    if (std::memcmp(a.ptr(y), b.ptr(y), a.cols * a.elemSize()) != 0) return false;
  }
  return true;
}

}  // namespace mapless::testing
