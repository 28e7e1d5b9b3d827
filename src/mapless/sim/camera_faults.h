// Simulated camera faults for hardening tests: for a time window the camera delivers black
// frames, the same frame again (frozen), nothing (a dropped source), over-exposed frames or a
// featureless view (a blank wall filling the image). Outside every window the rendered image
// passes through unchanged. Deterministic (the featureless view's sensor noise is seeded).
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "mapless/core/rng.h"

namespace mapless::sim {

enum class CameraFaultKind { kBlack, kFrozen, kDropped, kOverExposed, kFeatureless };
const char* CameraFaultKindName(CameraFaultKind kind);  // "black", "frozen", "dropped", ...
// Parses a name of CameraFaultKindName; throws InputError naming the value otherwise.
CameraFaultKind ParseCameraFaultKind(const std::string& name);

struct CameraFaultWindow {
  CameraFaultKind kind = CameraFaultKind::kBlack;
  double start_s = 0.0;  // from the camera's first frame, inclusive
  double end_s = 0.0;    // exclusive
};

class FaultyCamera {
 public:
  explicit FaultyCamera(std::vector<CameraFaultWindow> windows = {}, std::uint64_t seed = 1);
  // The image the robot gets at time t_s for the rendered image `rendered`. Fault windows count
  // from the t_s of the first call.
  cv::Mat Apply(const cv::Mat& rendered, double t_s);
  // The fault active `since_first_s` after the first frame, if any.
  const CameraFaultWindow* Active(double since_first_s) const;

 private:
  std::vector<CameraFaultWindow> windows_;
  Rng rng_;
  bool started_ = false;
  double first_t_s_ = 0.0;
  cv::Mat last_delivered_;  // what a frozen driver re-delivers
};

}  // namespace mapless::sim
