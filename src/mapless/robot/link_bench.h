// What the middleware adapters' latency benches share (ros1/link_bench.h, ros2/link_bench.h):
// frames published on loopback into a link whose method answers at once, so that what is measured
// is what the adapter adds: receiving and converting the image, handing it to the loop, publishing
// the Twist and the status.
#pragma once

#include <algorithm>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "mapless/robot/method.h"

namespace mapless::robot {

struct LinkBenchOptions {
  int frames = 300;
  double rate_hz = 50.0;
  cv::Size camera{320, 240};       // published size
  std::string encoding = "mono8";  // mono8 or rgb8
  cv::Size method{320, 240};       // the size the method wants (resized by the link)
};

struct LinkBenchResult {
  int frames = 0;  // decided on
  // Frame received (the subscriber callback) to command published, ms.
  double adapter_median_ms = 0.0;
  double adapter_p99_ms = 0.0;
  // Frame published to command received by another participant on loopback, ms.
  double end_to_end_median_ms = 0.0;
  double end_to_end_p99_ms = 0.0;
};

// Answers every frame at once with a command that encodes the frame's stamp (its sub-second part,
// in angular.z), so that a listener can pair command and frame.
class EchoMethod : public Method {
 public:
  explicit EchoMethod(cv::Size size) : size_(size) {}
  const char* name() const override { return "bench"; }
  bool needs_odometry() const override { return false; }
  cv::Size image_size() const override { return size_; }
  Decision Step(const Observation& o) override {
    Decision d;
    d.state = MethodState::kDriving;
    d.status = "driving";
    d.command = Twist2{0.1, static_cast<double>(o.t_ns % 1000000000) * 1e-9};
    return d;
  }

 private:
  cv::Size size_;
};

inline double Percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const auto i = static_cast<std::size_t>(std::min<double>(v.size() - 1, p * (v.size() - 1) + 0.5));
  return v[i];
}

}  // namespace mapless::robot
