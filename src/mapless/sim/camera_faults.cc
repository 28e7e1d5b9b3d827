#include "mapless/sim/camera_faults.h"

#include <cmath>

#include "mapless/core/check.h"

namespace mapless::sim {

const char* CameraFaultKindName(CameraFaultKind kind) {
  switch (kind) {
    case CameraFaultKind::kBlack:
      return "black";
    case CameraFaultKind::kFrozen:
      return "frozen";
    case CameraFaultKind::kDropped:
      return "dropped";
    case CameraFaultKind::kOverExposed:
      return "over-exposed";
    case CameraFaultKind::kFeatureless:
      return "featureless";
  }
  return "?";
}

CameraFaultKind ParseCameraFaultKind(const std::string& name) {
  for (CameraFaultKind k :
       {CameraFaultKind::kBlack, CameraFaultKind::kFrozen, CameraFaultKind::kDropped,
        CameraFaultKind::kOverExposed, CameraFaultKind::kFeatureless}) {
    if (name == CameraFaultKindName(k)) return k;
  }
  throw InputError("camera fault '" + name +
                   "' is not one of black, frozen, dropped, over-exposed, featureless");
}

FaultyCamera::FaultyCamera(std::vector<CameraFaultWindow> windows, std::uint64_t seed)
    : windows_(std::move(windows)), rng_(seed) {
  for (const CameraFaultWindow& w : windows_) {
    if (!(w.end_s > w.start_s)) {
      throw InputError("camera fault window [" + std::to_string(w.start_s) + ", " +
                       std::to_string(w.end_s) + ") s is empty");
    }
  }
}

const CameraFaultWindow* FaultyCamera::Active(double since_first_s) const {
  for (const CameraFaultWindow& w : windows_) {
    if (since_first_s >= w.start_s && since_first_s < w.end_s) return &w;
  }
  return nullptr;
}

cv::Mat FaultyCamera::Apply(const cv::Mat& rendered, double t_s) {
  if (!started_) {
    started_ = true;
    first_t_s_ = t_s;
  }
  // Rounded to the microsecond so that frame times a period apart land in the same window
  // however the sum of periods rounds.
  const CameraFaultWindow* fault = Active(std::round((t_s - first_t_s_) * 1e6) / 1e6);
  cv::Mat out;
  if (fault == nullptr) {
    out = rendered;
  } else {
    switch (fault->kind) {
      case CameraFaultKind::kBlack:
        out = cv::Mat::zeros(rendered.size(), rendered.type());
        break;
      case CameraFaultKind::kFrozen:
        out = last_delivered_.empty() ? rendered : last_delivered_;
        break;
      case CameraFaultKind::kDropped:
        return cv::Mat();
      case CameraFaultKind::kOverExposed:
        // Eight times the exposure: everything but the darkest texels clips at 255.
        rendered.convertTo(out, -1, 8.0, 0.0);
        break;
      case CameraFaultKind::kFeatureless: {
        // A uniformly lit blank wall filling the view, with one grey level of sensor noise.
        out.create(rendered.size(), rendered.type());
        auto* p = out.ptr<std::uint8_t>(0);
        const std::size_t n = out.total() * out.elemSize();
        for (std::size_t i = 0; i < n; ++i) {
          p[i] = cv::saturate_cast<std::uint8_t>(150.0 + rng_.Normal());
        }
        break;
      }
    }
  }
  last_delivered_ = out;
  return out;
}

}  // namespace mapless::sim
