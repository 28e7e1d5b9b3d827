// The ROS 1 adapter's own latency (issue 17): frames published on loopback into a Ros1Link whose
// method answers at once, so what is measured is what the adapter adds: receiving and converting
// the image, handing it to the loop, publishing the Twist and the status. Needs a ROS master
// (ROS_MASTER_URI); `mapless bench` starts one on loopback when rosmaster is installed.
#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace mapless::ros1 {

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
  // Frame published to command received by another node on loopback (TCPROS both ways), ms.
  double end_to_end_median_ms = 0.0;
  double end_to_end_p99_ms = 0.0;
};

LinkBenchResult BenchLink(const LinkBenchOptions& options);

}  // namespace mapless::ros1
