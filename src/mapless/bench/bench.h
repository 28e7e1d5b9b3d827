// `mapless bench`: per-stage medians in milliseconds on one thread, next to a stock OpenCV
// primitive measured in the same run, so that the ratio means the same on any machine; and the
// links' latencies (the robot middlewares, the fleet). The command (apps/cmd_bench.cc) parses its
// options, calls these and prints the table.
#pragma once

#include <nlohmann/json.hpp>
#include <opencv2/core/types.hpp>
#include <string>
#include <vector>

#include "mapless/robot/middleware.h"

namespace mapless::bench {

struct StageOptions {
  int repeats = 100;  // timed calls per stage
  // Views rendered along these scenarios' taught paths; empty: narrow_room_sharp_turn,
  // outdoor_70m and office_aliasing.
  std::vector<std::string> scenarios;
  cv::Size frame;  // every stage's frame size; 0x0: 320x240 (the JSON keys keep "320x240")
};

// Every method stage; sets OpenCV to one thread.
nlohmann::json BenchStages(const StageOptions& options);
// The stages of each method (added to `j`; BenchStages calls them).
void BenchTeachRepeat(nlohmann::json* j);
void BenchPotential(int repeats, nlohmann::json* j);
void BenchEigenspace(int repeats, nlohmann::json* j);
// Issue 66: the shift on a 512x192 pair against ORB-500, the sequence filter's step on a
// 1200-image route against DIS fast (real_images.cc).
void BenchRealImageStages(int repeats, nlohmann::json* j);
// A middleware's adapter latency, frame received to command published ("ros1", "ros2"); a row
// saying why when it is not built or could not be measured.
void BenchMiddleware(const robot::MiddlewareRegistry& middlewares, const std::string& middleware,
                     nlohmann::json* j);
// The fleet link on loopback: record latency, a late follower's catch-up, a follower's work per
// live record.
void BenchFleet(nlohmann::json* j);
// The live view on loopback (issue 43): the repeat loop's per-frame time with 0 and 3 clients (one
// stalled), and the latency from the loop to a client at 30 frames a second.
void BenchLive(nlohmann::json* j);

// The tables, to stdout.
void PrintStageTable(const nlohmann::json& j);  // the stages and then the links
void PrintLinkTable(const nlohmann::json& j);

// What `mapless bench` was asked for; RunBench measures it and prints the table or the JSON.
struct BenchRequest {
  bool json = false;
  int repeats = 100;
  std::string scenario;  // empty: the default mix of indoor, outdoor and aliasing scenes
  std::string size;      // WxH; empty: 320x240
  bool ros1 = false, ros2 = false, fleet = false, live = false;
  bool links_only = false;  // only the link rows: at least one of them must be asked for
};
void RunBench(const BenchRequest& request, const robot::MiddlewareRegistry& middlewares);

}  // namespace mapless::bench
