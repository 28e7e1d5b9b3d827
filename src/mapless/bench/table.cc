// The table `mapless bench` prints (bench.h): each stage's median and the ratios with the targets
// of the issues that set them.
#include <cstdio>
#include <iostream>
#include <nlohmann/json.hpp>
#include <string>

#include "mapless/bench/bench.h"
#include "mapless/core/check.h"
#include "mapless/io/image_file.h"

namespace mapless::bench {

namespace {

// The robot-link rows of the table (issues 17, 18), for the middlewares that were measured.
void PrintLinkRows(const nlohmann::json& j) {
  for (const char* kind : {"eigenspace", "funnel"}) {
    const std::string k = std::string("fleet_latency_") + kind;
    if (!j.contains(k + "_median_ms")) continue;
    std::printf("%-34s %10.3f  p99 %.3f  (target: p99 <= 5)\n",
                ("fleet record latency " + std::string(kind)).c_str(),
                j[k + "_median_ms"].get<double>(), j[k + "_p99_ms"].get<double>());
    std::printf("%-34s %10.3f  s (target: <= 1 s; %d-byte records)\n",
                ("fleet catch-up 1000 " + std::string(kind)).c_str(),
                j[std::string("fleet_catch_up_1000_") + kind + "_s"].get<double>(),
                j[std::string("fleet_record_bytes_") + kind].get<int>());
    if (j.contains("fleet_model_rebuild_1000_s") && std::string(kind) == "eigenspace")
      std::printf("%-34s %10.3f  s (the eigenspace of 1000 images, once caught up)\n",
                  "fleet model rebuild 1000", j["fleet_model_rebuild_1000_s"].get<double>());
  }
  if (j.contains("fleet_follower_read_pieces_first100_ms")) {
    std::printf("%-34s %10.3f  last 100: %.3f ms (target: flat; whole snapshot %.3f -> %.3f)\n",
                "fleet follower read/record, first 100",
                j["fleet_follower_read_pieces_first100_ms"].get<double>(),
                j["fleet_follower_read_pieces_last100_ms"].get<double>(),
                j["fleet_follower_read_snapshot_first100_ms"].get<double>(),
                j["fleet_follower_read_snapshot_last100_ms"].get<double>());
    std::printf("%-34s %10.3f  last 100: %.3f ms (files flushed, manifest rewritten)\n",
                "fleet follower apply/record, first 100",
                j["fleet_follower_apply_first100_ms"].get<double>(),
                j["fleet_follower_apply_last100_ms"].get<double>());
  }
  if (j.contains("live_loop_3_over_0_clients")) {
    std::printf("%-34s %10.3f  3 clients (1 stalled): %.3f ms, %.3fx (target: <= 1.05x)\n",
                "live view: repeat loop, 0 clients", j["live_loop_0_clients_ms"].get<double>(),
                j["live_loop_3_clients_ms"].get<double>(),
                j["live_loop_3_over_0_clients"].get<double>());
    std::printf("%-34s %10.3f  p99 %.3f ms, %d frames at 30 fps (target: p99 <= 20)\n",
                "live view: frame to client", j["live_latency_median_ms"].get<double>(),
                j["live_latency_p99_ms"].get<double>(), j["live_latency_samples"].get<int>());
  }
  if (j.contains("live_hostile_over_0_clients")) {
    std::printf(
        "%-34s %10.3f  hostile clients: %.3f ms, %.3fx (target: <= 1.05x, docs/hardening.md)\n",
        "live view: repeat loop, 0 clients", j["live_hostile_loop_0_clients_ms"].get<double>(),
        j["live_hostile_loop_ms"].get<double>(), j["live_hostile_over_0_clients"].get<double>());
    std::printf(
        "%-34s %10d  in %.1f s (%d not shown), %d cut off, %d refused, peak %.0f MB\n",
        "live view: hostile, lines logged", j["live_hostile_log_lines"].get<int>(),
        j["live_hostile_seconds"].get<double>(), j["live_hostile_log_lines_suppressed"].get<int>(),
        j["live_hostile_clients_cut_off"].get<int>(),
        j["live_hostile_connections_refused"].get<int>(), j["live_peak_rss_mb"].get<double>());
    std::printf("%-34s %10.3f  run s per wall s at --live-rate %.1f\n", "live view: pacing",
                j["live_pace_run_s_per_wall_s"].get<double>(), j["live_pace_rate"].get<double>());
  }
  for (const char* mw : {"ros1", "ros2"}) {
    const std::string prefix = std::string(mw) + "_link";
    if (j.contains(prefix)) {
      std::printf("%-34s %s\n", prefix.c_str(), j[prefix].get<std::string>().c_str());
      continue;
    }
    for (const char* cam : {"320x240_mono8", "640x480_rgb8"}) {
      const std::string k = prefix + "_" + cam;
      if (!j.contains(k + "_adapter_median_ms")) continue;
      std::printf("%-34s %10.3f  p99 %.3f  (issues 17, 18: p99 <= 5)\n",
                  (std::string(mw) + " adapter " + cam).c_str(),
                  j[k + "_adapter_median_ms"].get<double>(),
                  j[k + "_adapter_p99_ms"].get<double>());
      std::printf("%-34s %10.3f  p99 %.3f\n", (std::string(mw) + " end to end " + cam).c_str(),
                  j[k + "_end_to_end_median_ms"].get<double>(),
                  j[k + "_end_to_end_p99_ms"].get<double>());
    }
  }
}

}  // namespace

void PrintStageTable(const nlohmann::json& j) {
  // Every stage runs on one thread (cv::setNumThreads(1)) but those named "2_threads"; fps: the
  // frame rate the stage alone allows on this host (1000 / median).
  std::printf("%-40s %10s %9s\n", "stage (one thread; 2_threads: two)", "median ms", "fps");
  for (const char* key : {"sim_render_320x240_ms",
                          "sim_render_baseline_kernels_320x240_ms",
                          "opencv_dis_fast_320x240_ms",
                          "teach_step_ms",
                          "teach_step_2_threads_ms",
                          "repeat_step_default_ms",
                          "repeat_step_default_mean_ms",
                          "repeat_step_default_p90_ms",
                          "repeat_step_default_with_watch_ms",
                          "repeat_step_default_with_watch_2_threads_ms",
                          "obstacle_watch_ms",
                          "opencv_dis_fast_table1_320x240_ms",
                          "repeat_step_ms",
                          "repeat_step_1km_ms",
                          "repeat_step_fresh_ms",
                          "repeat_step_fresh_end_ms",
                          "repeat_step_fresh_1km_ms",
                          "segment_start_ms",
                          "opencv_orb500_320x240_ms",
                          "opencv_orb500_interleaved_ms",
                          "opencv_orb_mapless_settings_320x240_ms",
                          "orb_detector_320x240_ms",
                          "dense_lk_320x240_ms",
                          "dense_lk_baseline_kernels_320x240_ms",
                          "opencv_pyrlk_every_pixel_320x240_ms",
                          "opencv_dis_fast_ground_320x240_ms",
                          "dominant_plane_step_ms",
                          "dominant_plane_step_dis_medium_ms",
                          "dominant_plane_step_dis_medium_2_threads_ms",
                          "ipca_add_1000_ms",
                          "markov_update_10000_ms",
                          "subwindow_control_ms",
                          "opencv_orb500_512x192_ms",
                          "shift_pair_512x192_ms",
                          "shift_step_512x192_ms",
                          "opencv_dis_fast_real_320x240_ms",
                          "sequence_filter_step_1200_ms"}) {
    const double ms = j[key].get<double>();
    std::printf("%-40s %10.3f %9.0f\n", key, ms, ms > 0.0 ? 1000.0 / ms : 0.0);
  }
  std::printf("%-34s %10.2f  (target: <= 1.0; %s kernels)\n", "sim_render / dis_fast",
              j["sim_render_over_dis_fast"].get<double>(),
              j["sim_render_kernels"].get<std::string>().c_str());
  std::printf("%-34s %10.2f  (the same images without AVX2)\n", "sim_render baseline / dis_fast",
              j["sim_render_baseline_kernels_over_dis_fast"].get<double>());
  std::printf("%-34s %10.2f  (target: <= 1.5)\n", "repeat_step / orb500",
              j["repeat_step_over_orb"].get<double>());
  std::printf("%-34s %10.2f  (target: <= 1.5; ORB-500 timed after each step)\n",
              "repeat_step / orb500 interl.", j["repeat_step_over_orb_interleaved"].get<double>());
  std::printf("%-34s %10.2f  (target: <= 1.5)\n", "repeat_step_default / orb500",
              j["repeat_step_default_over_orb"].get<double>());
  std::printf("%-34s %10.2f  (target: <= 1.5; ORB-500 timed after each step)\n",
              "repeat_step_default / orb500 interl.",
              j["repeat_step_default_over_orb_interleaved"].get<double>());
  std::printf("%-34s %10.2f  (target: <= 2.0; ORB-500 timed after each step)\n",
              "teach_step / orb500 interl.", j["teach_step_over_orb_interleaved"].get<double>());
  std::printf("%-34s %10.2f  (target: <= 2.0; KLT in two halves on two threads)\n",
              "teach_step 2 threads / orb500",
              j["teach_step_2_threads_over_orb_interleaved"].get<double>());
  std::printf("%-34s %10.2f  (target: <= 1.5; ORB-500 timed after each step)\n",
              "repeat_step_with_watch / orb500 int.",
              j["repeat_step_default_with_watch_over_orb_interleaved"].get<double>());
  std::printf("%-34s %10.2f  (target: <= 1.5; the watch on a second thread)\n",
              "repeat_step_with_watch 2 thr / orb500",
              j["repeat_step_default_with_watch_2_threads_over_orb_interleaved"].get<double>());
  if (j.contains("repeat_step_5_views_over_1")) {
    std::printf("%-34s %10.2f  (target: <= 1.3; mean %.2f)\n", "repeat_step 5 views / 1 view",
                j["repeat_step_5_views_over_1"].get<double>(),
                j["repeat_step_5_views_over_1_mean"].get<double>());
  }
  std::printf("%-34s %10.2f  (same keypoints and descriptors)\n",
              "orb_detector / opencv same settings",
              j["orb_detector_over_opencv_same_settings"].get<double>());
  std::printf("%-34s %10.2f\n", "repeat_step_default_mean / orb500",
              j["repeat_step_default_mean_over_orb"].get<double>());
  std::printf("%-34s %10.2f  (target: <= 1.0)\n", "obstacle_watch / dis_fast",
              j["obstacle_watch_over_dis_fast"].get<double>());
  std::printf("%-34s %10.2f\n", "repeat_step_fresh / orb500",
              j["repeat_step_fresh_over_orb"].get<double>());
  std::printf("%-34s %10.2f  (target: <= 6.0)\n", "segment_start / orb500",
              j["segment_start_over_orb"].get<double>());
  std::printf("%-34s %10.2f  (target: >= 100; %s kernels)\n", "pyrlk_every_pixel / dense_lk",
              j["pyrlk_every_pixel_over_dense_lk"].get<double>(),
              j["dense_lk_kernels"].get<std::string>().c_str());
  std::printf("%-34s %10.2f  (the same flow without AVX2)\n", "pyrlk_every_pixel / dense_lk base",
              j["pyrlk_every_pixel_over_dense_lk_baseline_kernels"].get<double>());
  std::printf("%-34s %10.2f  (target: <= 2.0)\n", "dominant_plane_step / dis_fast",
              j["dominant_plane_step_over_dis_fast"].get<double>());
  std::printf("%-34s %10.2f  (target: <= 2.0; the navigator's default, DIS medium)\n",
              "navigator_default / dis_fast", j["navigator_default_over_dis_fast"].get<double>());
  std::printf("%-34s %10.2f  (target: <= 2.0; the flow on two threads, a robot file's default)\n",
              "navigator_default 2 thr / dis_fast",
              j["navigator_default_2_threads_over_dis_fast"].get<double>());
  for (const char* key : {"ipca_add_1000", "markov_update_10000", "subwindow_control"}) {
    std::printf("%-34s %10.2f  (target: <= 1.5)\n", (std::string(key) + " / dis_fast").c_str(),
                j[std::string(key) + "_over_dis_fast"].get<double>());
  }
  std::printf("%-34s %10.2f  (target: <= 10; both images described)\n",
              "shift_pair / orb500 512x192", j["shift_pair_over_orb500"].get<double>());
  std::printf("%-34s %10.2f  (the taught view described once, as a repeat does)\n",
              "shift_step / orb500 512x192", j["shift_step_over_orb500"].get<double>());
  std::printf("%-34s %10.2f  (target: <= 1.0)\n", "sequence_filter_1200 / dis_fast",
              j["sequence_filter_step_over_dis_fast"].get<double>());
  PrintLinkRows(j);
}

void PrintLinkTable(const nlohmann::json& j) { PrintLinkRows(j); }

void RunBench(const BenchRequest& request, const robot::MiddlewareRegistry& middlewares) {
  const BenchRequest& r = request;
  if (r.links_only && !r.ros1 && !r.ros2 && !r.fleet && !r.live)
    throw InputError("--links-only: add --ros1, --ros2, --fleet and/or --live-view");
  nlohmann::json j;
  if (!r.links_only) {
    StageOptions options;
    options.repeats = r.repeats;
    if (!r.scenario.empty()) options.scenarios = {r.scenario};
    if (!r.size.empty()) options.frame = io::ParseFrameSize(r.size, "--size", {64, 48});
    j = BenchStages(options);
  }
  if (r.ros1) BenchMiddleware(middlewares, "ros1", &j);
  if (r.ros2) BenchMiddleware(middlewares, "ros2", &j);
  if (r.fleet) BenchFleet(&j);
  if (r.live) BenchLive(&j);
  if (r.json) {
    std::cout << j.dump() << "\n";
  } else if (r.links_only) {
    PrintLinkTable(j);
  } else {
    PrintStageTable(j);
  }
}

}  // namespace mapless::bench
