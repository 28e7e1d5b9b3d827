// `mapless bench --fleet`: the fleet link on loopback (issue 19). A leader's RouteCopy served by a
// LeaderServer, a follower's RouteCopy kept by a FollowerClient, both in this process over TCP on
// 127.0.0.1: record latency (the leader's write, after its files are flushed, to the follower's
// receive; target p99 <= 5 ms) and the catch-up of a follower joining a 1000-record route late
// (every record received, checked, written with the route store's crash safety and, for the
// eigenspace, the model rebuilt; target <= 1 s).
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <thread>

#include "mapless/bench/bench.h"
#include "mapless/bench/timing.h"
#include "mapless/core/rng.h"
#include "mapless/fleet/client.h"
#include "mapless/fleet/route_log.h"
#include "mapless/fleet/server.h"
#include "mapless/robot/link_bench.h"

namespace mapless::bench {

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

// Records like a taught route's: 64x64 route images with texture, or keyframes of 500 ORB
// features (their YAML is about 100 KB, as a simulator teach writes).
fleet::Record BenchRecord(fleet::RouteKind kind, int index) {
  Rng rng(static_cast<std::uint64_t>(index) + 11);
  if (kind == fleet::RouteKind::kEigenspace) {
    route::StoredAppearanceImage image;
    image.low = cv::Mat(64, 64, CV_8UC1);
    for (int r = 0; r < 64; ++r)
      for (int c = 0; c < 64; ++c)
        image.low.at<std::uint8_t>(r, c) = static_cast<std::uint8_t>(
            128 + 60 * std::sin(0.3 * c + 0.1 * index) + rng.Uniform(-20, 20));
    image.distance_m = 0.2 * index;
    image.odometry = Pose2{0.2 * index, 0.0, 0.0};
    return fleet::ImageRecord(image);
  }
  route::Keyframe kf;
  kf.index = index;
  kf.t_ns = 1'000'000'000LL * (index + 1);
  kf.thumbnail = cv::Mat(60, 80, CV_8UC1);
  cv::RNG fill(static_cast<std::uint64_t>(index) + 13);
  fill.fill(kf.thumbnail, cv::RNG::UNIFORM, 0, 256);
  for (int i = 0; i < 500; ++i) {
    const auto angle = static_cast<float>(rng.Uniform(0, 360));  // one order for every compiler
    const auto y = static_cast<float>(rng.Uniform(0, 239));
    const auto x = static_cast<float>(rng.Uniform(0, 319));
    kf.keypoints.emplace_back(x, y, 31.0f, angle, 0.001f, 0);
  }
  kf.descriptors = cv::Mat(500, 32, CV_8UC1);
  fill.fill(kf.descriptors, cv::RNG::UNIFORM, 0, 256);
  if (index > 0) {
    for (int i = 0; i < 100; ++i) {
      kf.segment_start_px.emplace_back(static_cast<float>(rng.Uniform(0, 319)), 120.0f);
      kf.segment_end_px.emplace_back(static_cast<float>(rng.Uniform(0, 319)), 121.0f);
    }
  }
  return fleet::KeyframeRecord(kf);
}

fleet::RouteHeader BenchHeader(fleet::RouteKind kind) {
  fleet::RouteHeader h;
  h.kind = kind;
  h.image_width = 320;
  h.image_height = 240;
  h.low_width = 64;
  h.low_height = 64;
  return h;
}

bool WaitUntil(const std::function<bool()>& done, double seconds) {
  const auto until = Clock::now() + std::chrono::duration<double>(seconds);
  while (!done() && Clock::now() < until)
    std::this_thread::sleep_for(std::chrono::microseconds(200));
  return done();
}

double Percentile(const std::vector<double>& v, double p) {  // -1: nothing measured
  return v.empty() ? -1.0 : robot::Percentile(v, p);
}

// A follower's work per live record on a 1000-keyframe route: the record applied to its copy, then
// the route read by its method, one record at a time, as while the leader teaches. The method's
// read in pieces (RouteCopy::UpdateFunnel) against the whole-route snapshot it used to take
// (RouteCopy::FunnelRoute); medians over the first and the last 100 records.
void BenchFollowerPerRecord(const std::string& root, nlohmann::json* j) {
  constexpr int kRecords = 1000;
  std::vector<fleet::Record> records = {
      fleet::HeaderRecord(BenchHeader(fleet::RouteKind::kFunnel))};
  for (int i = 0; i < kRecords; ++i) records.push_back(BenchRecord(fleet::RouteKind::kFunnel, i));
  for (std::size_t i = 0; i < records.size(); ++i) records[i].sequence = i;
  for (const bool pieces : {true, false}) {
    fleet::RouteCopy copy(root + (pieces ? "/per_record_pieces" : "/per_record_snapshot"));
    route::Route route;
    std::vector<double> apply_ms, read_ms;
    for (const fleet::Record& r : records) {
      const auto t0 = Clock::now();
      copy.Apply({r});
      const auto t1 = Clock::now();
      const std::size_t n = pieces
                                ? (copy.UpdateFunnel(&route), route.keyframes.size())
                                : (copy.FunnelRoute() ? copy.FunnelRoute()->keyframes.size() : 0);
      const auto t2 = Clock::now();
      if (n == 0 && r.sequence > 2) throw std::runtime_error("bench: the follower read no route");
      apply_ms.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
      read_ms.push_back(std::chrono::duration<double, std::milli>(t2 - t1).count());
    }
    const auto first = [](const std::vector<double>& v) {
      return Median(std::vector<double>(v.begin() + 1, v.begin() + 101));
    };
    const auto last = [](const std::vector<double>& v) {
      return Median(std::vector<double>(v.end() - 100, v.end()));
    };
    const std::string name = pieces ? "pieces" : "snapshot";
    (*j)["fleet_follower_read_" + name + "_first100_ms"] = first(read_ms);
    (*j)["fleet_follower_read_" + name + "_last100_ms"] = last(read_ms);
    if (pieces) {
      (*j)["fleet_follower_apply_first100_ms"] = first(apply_ms);
      (*j)["fleet_follower_apply_last100_ms"] = last(apply_ms);
    }
  }
}

}  // namespace

void BenchFleet(nlohmann::json* j) {
  const std::string root =
      (fs::temp_directory_path() / ("mapless-bench-fleet-" + std::to_string(::getpid()))).string();
  fs::remove_all(root);
  for (const fleet::RouteKind kind : {fleet::RouteKind::kEigenspace, fleet::RouteKind::kFunnel}) {
    const std::string name = fleet::RouteKindName(kind);
    constexpr int kRecords = 1000;
    fleet::RouteCopy leader(root + "/" + name + "_leader");
    std::vector<fleet::Record> records = {fleet::HeaderRecord(BenchHeader(kind))};
    for (int i = 0; i < kRecords; ++i) records.push_back(BenchRecord(kind, i));
    for (std::size_t i = 0; i < records.size(); ++i) records[i].sequence = i;
    leader.Apply(records);
    fleet::ServerOptions server_options;
    server_options.bind = "tcp://127.0.0.1:*";
    fleet::LeaderServer server(leader, server_options, nullptr);
    fleet::ClientOptions client_options;
    client_options.connect = server.endpoint();
    // Catch-up: a new follower, the whole route; three times, the median.
    std::vector<double> catch_up;
    for (int run = 0; run < 3; ++run) {
      fleet::RouteCopy copy(root + "/" + name + "_late" + std::to_string(run));
      const auto t0 = Clock::now();
      fleet::FollowerClient client(copy, client_options, nullptr);
      const bool ok = WaitUntil([&] { return copy.next_sequence() == records.size(); }, 120.0);
      catch_up.push_back(ok ? std::chrono::duration<double>(Clock::now() - t0).count() : -1.0);
    }
    (*j)["fleet_catch_up_1000_" + name + "_s"] = Percentile(catch_up, 0.5);
    if (kind == fleet::RouteKind::kEigenspace) {
      // The model, built once the copy has caught up (when the follower's method first asks).
      fleet::RouteCopy copy(root + "/" + name + "_late0");
      const auto t0 = Clock::now();
      const bool built = copy.AppearanceRoute() != nullptr;
      (*j)["fleet_model_rebuild_1000_s"] =
          built ? std::chrono::duration<double>(Clock::now() - t0).count() : -1.0;
    }
    (*j)["fleet_record_bytes_" + name] =
        records.back().parts[0].size() + records.back().parts[1].size();
    // Latency: a caught-up follower, then 300 live records 10 ms apart.
    fleet::RouteCopy live(root + "/" + name + "_live");
    fleet::FollowerClient client(live, client_options, nullptr);
    WaitUntil([&] { return live.next_sequence() == records.size(); }, 120.0);
    for (int i = kRecords; i < kRecords + 300; ++i) {
      fleet::Record r = BenchRecord(kind, i);
      r.sequence = leader.next_sequence();
      leader.Apply({r});
      server.Notify();
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    WaitUntil([&] { return live.next_sequence() == leader.next_sequence(); }, 30.0);
    const std::vector<double> latency = client.stats().latency_ms;
    (*j)["fleet_latency_" + name + "_samples"] = latency.size();
    (*j)["fleet_latency_" + name + "_median_ms"] = Percentile(latency, 0.5);
    (*j)["fleet_latency_" + name + "_p99_ms"] = Percentile(latency, 0.99);
  }
  BenchFollowerPerRecord(root, j);
  fs::remove_all(root);
}

}  // namespace mapless::bench
