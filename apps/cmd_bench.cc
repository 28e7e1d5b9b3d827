// `mapless bench`: per-stage medians in milliseconds on one thread, on 320x240 frames, next to a
// stock OpenCV primitive measured in the same run so that the ratio is meaningful on any machine.
// Later issues add their stages here.
#include <algorithm>
#include <chrono>
#include <functional>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/video/tracking.hpp>
#include <sstream>

#include "bench_util.h"
#include "cli_common.h"
#include "mapless/appearance/image.h"
#include "mapless/appearance/pca.h"
#include "mapless/appearance/subwindow.h"
#include "mapless/control/subwindow_steering.h"
#include "mapless/core/check.h"
#include "mapless/eval/potential.h"
#include "mapless/eval/teach_repeat.h"
#include "mapless/flow/flow.h"
#include "mapless/localization/markov.h"
#include "mapless/sim/driver.h"

namespace mapless::app {

// The middleware's robot-link latency rows (bench_links.cc).
void BenchMiddleware(const std::string& middleware, nlohmann::json* j);
void BenchFleet(nlohmann::json* j);        // bench_fleet.cc
void BenchTeachRepeat(nlohmann::json* j);  // bench_repeat.cc

namespace {

// Poses along a scenario's taught path (ground truth of a clean drive), for typical views.
std::vector<Pose2> PosesAlong(const sim::Scenario& scenario, int count) {
  std::vector<Pose2> poses;
  sim::Simulation s(scenario.world, scenario.camera, {}, 1);
  s.AddRobot(scenario.teach_start, scenario.robot);
  sim::ScriptedDriver driver(scenario.teach_start, scenario.teach_path, scenario.teach_speed_mps);
  while (!driver.done() && poses.size() < 5000) {
    poses.push_back(s.robot(0).pose());
    s.SetCommand(0, driver.Update(s.robot(0).pose()));
    s.Advance(0.1);
  }
  std::vector<Pose2> picked;
  for (int i = 0; i < count; ++i) {
    picked.push_back(
        poses[static_cast<std::size_t>(i) * poses.size() / static_cast<std::size_t>(count)]);
  }
  return picked;
}

// Issue 4: one visual-potential control step (flow + dominant plane + potential + command) on
// the downward camera of the corridor scenario, against DIS fast alone on the same frames.
void BenchPotential(int repeats, nlohmann::json* j) {
  const sim::Scenario scenario = BenchScenario("corridor_straight_3p5m");
  navigation::PotentialNavOptions nav;
  const navigation::PlanarFlowCalibration calibration = eval::CalibrateOnSimulator(scenario, nav);
  std::vector<cv::Mat> frames;
  std::vector<Pose2> poses;
  {
    sim::Simulation drive(scenario.world, scenario.camera, {}, 1);
    drive.AddRobot(scenario.teach_start, scenario.robot);
    drive.SetCommand(0, Twist2{0.2, 0.05});
    drive.Advance(1.0);
    for (int k = 0; k < 12; ++k) {
      frames.push_back(drive.RenderClean(0));
      poses.push_back(drive.robot(0).pose());
      drive.Advance(0.1);
    }
  }
  auto dis = cv::DISOpticalFlow::create(cv::DISOpticalFlow::PRESET_FAST);
  cv::Mat flow;
  (*j)["opencv_dis_fast_ground_320x240_ms"] = MedianMs(repeats, 3, [&](int i) {
    const auto k = static_cast<std::size_t>(i) % (frames.size() - 1);
    dis->calc(frames[k], frames[k + 1], flow);
  });
  // The measure: the step with DIS fast; and the navigator's default (DIS medium).
  auto time_step = [&](flow::FlowMethod method) {
    navigation::PotentialNavOptions o = nav;
    o.flow.method = method;
    navigation::PotentialNavigator navigator(calibration, o);
    Pose2 odometry;
    int calls = 0;
    auto step = [&] {
      // Odometry moves 2 cm per call so every call computes flow (cycling the frames).
      odometry = odometry * Pose2{0.02, 0.0, 0.0};
      navigator.Update(frames[static_cast<std::size_t>(calls++) % frames.size()], odometry);
    };
    step();
    return MedianMs(repeats, 3, [&](int) { step(); });
  };
  (*j)["dominant_plane_step_ms"] = time_step(flow::FlowMethod::kDisFast);
  (*j)["dominant_plane_step_dis_medium_ms"] = time_step(flow::FlowMethod::kDisMedium);
  (*j)["dominant_plane_step_over_dis_fast"] =
      (*j)["dominant_plane_step_ms"].get<double>() /
      (*j)["opencv_dis_fast_ground_320x240_ms"].get<double>();
}

// Issue 5: incremental PCA, Markov localization and sub-window steering (Payá et al.), on the
// images of a drive along outdoor_70m.
void BenchEigenspace(int repeats, nlohmann::json* j) {
  const sim::Scenario scenario = BenchScenario("outdoor_70m");
  const appearance::AppearanceImageOptions image_options;
  std::vector<appearance::Vector> vectors;
  std::vector<cv::Mat> frames;
  sim::DriveOptions drive;
  sim::DriveTaughtPath(scenario, drive, [&](const sim::DriveFrame& f) {
    vectors.push_back(appearance::AppearanceVector(f.image, image_options));
    if (f.index % 20 == 0) frames.push_back(f.image.clone());
  });
  // Route of 1000 images (the drive's frames, repeated with a little noise when it is shorter).
  appearance::IncrementalPca pca;
  cv::RNG rng(7);
  const auto noisy = [&](std::size_t k) {
    appearance::Vector v = vectors[k % vectors.size()];
    for (Eigen::Index p = 0; p < v.size(); ++p) v(p) += static_cast<float>(rng.gaussian(0.05));
    return v;
  };
  for (std::size_t k = 0; k < 1000; ++k) pca.Add(noisy(k));
  std::vector<double> ms;
  for (int r = 0; r < std::max(repeats, 10); ++r) {
    appearance::IncrementalPca copy = pca;
    const appearance::Vector x = noisy(static_cast<std::size_t>(r) * 7 + 3);
    const auto t0 = std::chrono::steady_clock::now();
    copy.Add(x);
    const auto t1 = std::chrono::steady_clock::now();
    ms.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
  }
  (*j)["ipca_add_1000_ms"] = Median(ms);
  (*j)["ipca_dimensions"] = pca.dimensions();

  // Markov localization over a 10,000-image route (the eigenspace's projections, tiled).
  const appearance::Eigenspace model = pca.Model();
  Eigen::MatrixXf projections(model.projections.rows(), 10000);
  for (Eigen::Index c = 0; c < projections.cols(); ++c) {
    projections.col(c) =
        model.projections.col(c % model.projections.cols()) +
        Eigen::VectorXf::Constant(model.projections.rows(),
                                  0.01F * static_cast<float>(c / model.projections.cols()));
  }
  localization::MarkovLocalizer markov;
  markov.ResetAt(10000, 5000.0, 2.0);
  (*j)["markov_update_10000_ms"] = MedianMs(
      repeats, 3, [&](int i) { markov.Update(projections, projections.col(5000 + i % 50), 0.5); });

  // One steering decision: the camera image to its low resolution, the five query windows
  // matched in the route image's sub-window eigenspace, the seven fits.
  const appearance::SubWindowOptions windows;
  std::vector<appearance::SubWindowEigenspace> routes;
  for (const cv::Mat& f : frames) {
    routes.push_back(
        appearance::BuildSubWindowEigenspace(appearance::LowResolution(f, image_options), windows));
  }
  (*j)["subwindow_control_ms"] = MedianMs(repeats, 3, [&](int i) {
    const std::size_t k = static_cast<std::size_t>(i) % (frames.size() - 1);
    const cv::Mat low = appearance::LowResolution(frames[k + 1], image_options);
    std::vector<control::WindowCorrespondence> m;
    for (const auto& w : appearance::MatchSubWindows(routes[k], low, windows))
      m.push_back({w.query, w.stored});
    control::ComputeSubWindowSteering(m, routes[k].windows(), windows.step_px, {});
  });
  const double dis = (*j)["opencv_dis_fast_320x240_ms"].get<double>();
  (*j)["ipca_add_1000_over_dis_fast"] = (*j)["ipca_add_1000_ms"].get<double>() / dis;
  (*j)["markov_update_10000_over_dis_fast"] = (*j)["markov_update_10000_ms"].get<double>() / dis;
  (*j)["subwindow_control_over_dis_fast"] = (*j)["subwindow_control_ms"].get<double>() / dis;
}

}  // namespace

// The robot-link rows of the table (issues 17, 18), for the middlewares that were measured.
static void PrintLinkRows(const nlohmann::json& j) {
  for (const char* kind : {"eigenspace", "funnel"}) {
    const std::string k = std::string("fleet_latency_") + kind;
    if (!j.contains(k + "_median_ms")) continue;
    std::printf("%-34s %10.3f  p99 %.3f  (issue 19: p99 <= 5)\n",
                ("fleet record latency " + std::string(kind)).c_str(),
                j[k + "_median_ms"].get<double>(), j[k + "_p99_ms"].get<double>());
    std::printf("%-34s %10.3f  s (issue 19: <= 1 s; %d-byte records)\n",
                ("fleet catch-up 1000 " + std::string(kind)).c_str(),
                j[std::string("fleet_catch_up_1000_") + kind + "_s"].get<double>(),
                j[std::string("fleet_record_bytes_") + kind].get<int>());
    if (j.contains("fleet_model_rebuild_1000_s") && std::string(kind) == "eigenspace")
      std::printf("%-34s %10.3f  s (the eigenspace of 1000 images, once caught up)\n",
                  "fleet model rebuild 1000", j["fleet_model_rebuild_1000_s"].get<double>());
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

void AddBenchCommand(CLI::App* app) {
  struct Args {
    bool json = false;
    int repeats = 100;
    std::string scenario;  // empty: the default mix of indoor, outdoor and aliasing scenes
    bool ros1 = false;
    bool ros2 = false;
    bool links_only = false;
    std::string size;
    bool fleet = false;
  };
  auto args = std::make_shared<Args>();
  CLI::App* bench = app->add_subcommand(
      "bench",
      "Per-stage medians (ms, one thread, 320x240) with OpenCV references from the same run");
  bench->add_flag("--json", args->json, "Print one JSON object instead of a table");
  bench->add_option("--repeats", args->repeats, "Timed calls per stage")
      ->capture_default_str()
      ->check(CLI::Range(3, 100000));
  bench->add_option("--scenario", args->scenario,
                    "Render views of this scenario only (default: narrow_room_sharp_turn, "
                    "outdoor_70m and office_aliasing, 12 views along each taught path)");
  bench->add_option("--size", args->size,
                    "Frame size of every stage, WxH (default 320x240; e.g. 640x480 for a larger "
                    "camera; the JSON keys keep their 320x240)");
  bench->add_flag("--ros1", args->ros1,
                  "Also the ROS 1 adapter's latency, frame received to command published "
                  "(starts a ROS master on loopback)");
  bench->add_flag("--ros2", args->ros2,
                  "Also the ROS 2 (DDS) adapter's latency, frame received to command published "
                  "(a DDS domain of its own on loopback)");
  bench->add_flag("--fleet", args->fleet,
                  "Also the fleet link on loopback: record latency, leader's write to follower's "
                  "receive, and a late follower's catch-up on a 1000-record route");
  bench->add_flag("--links-only", args->links_only,
                  "Only the link rows (with --ros1, --ros2 and/or --fleet), not the method stages");
  bench->callback([args] {
    if (args->links_only) {
      if (!args->ros1 && !args->ros2 && !args->fleet)
        throw InputError("--links-only: add --ros1, --ros2 and/or --fleet");
      nlohmann::json j;
      if (args->ros1) BenchMiddleware("ros1", &j);
      if (args->ros2) BenchMiddleware("ros2", &j);
      if (args->fleet) BenchFleet(&j);
      if (args->json) {
        std::cout << j.dump() << "\n";
      } else {
        PrintLinkRows(j);
      }
      return;
    }
    if (!args->size.empty()) {
      int w = 0, h = 0;
      char x = 0;
      std::istringstream in(args->size);
      if (!(in >> w >> x >> h) || x != 'x' || !in.eof() || w < 64 || h < 48 || w > 4096 || h > 4096)
        throw InputError("--size '" + args->size + "': expected WxH, 64x48 to 4096x4096");
      BenchFrameSize() = cv::Size(w, h);
    }
    cv::setNumThreads(1);
    const std::vector<std::string> names =
        args->scenario.empty()
            ? std::vector<std::string>{"narrow_room_sharp_turn", "outdoor_70m", "office_aliasing"}
            : std::vector<std::string>{args->scenario};
    // Typical views: poses along each scenario's taught path, at 320x240 and 60 degrees.
    struct View {
      const sim::Renderer* renderer;
      sim::CameraSpec camera;
      Pose2 pose;
    };
    std::vector<std::unique_ptr<sim::Renderer>> renderers;
    std::vector<View> views;
    for (const std::string& name : names) {
      sim::Scenario scenario = sim::LoadScenario(name);
      scenario.camera.model = sim::CameraModel::FromFov(BenchFrameSize().width,
                                                        BenchFrameSize().height, DegToRad(60.0));
      renderers.push_back(std::make_unique<sim::Renderer>(scenario.world, sim::RenderOptions{}));
      for (const Pose2& p : PosesAlong(scenario, 12))
        views.push_back({renderers.back().get(), scenario.camera, p});
    }
    const sim::Scenario scenario = BenchScenario(names.front());

    nlohmann::json j;
    j["scenarios"] = names;
    j["threads"] = cv::getNumThreads();
    j["frame"] =
        std::to_string(BenchFrameSize().width) + "x" + std::to_string(BenchFrameSize().height);
    j["repeats"] = args->repeats;
    cv::Mat sink;
    j["sim_render_320x240_ms"] = MedianMs(args->repeats, 3, [&](int i) {
      const View& v = views[static_cast<std::size_t>(i) % views.size()];
      sink = v.renderer->Render(v.camera.model, sim::WorldFromCamera(v.pose, v.camera.mount));
    });
    // Reference: DIS optical flow (PRESET_FAST) on consecutive views of the same drive.
    std::vector<cv::Mat> pair_a;
    std::vector<cv::Mat> pair_b;
    {
      sim::Simulation drive(scenario.world, scenario.camera, {}, 1);
      drive.AddRobot(views[views.size() / 7].pose, scenario.robot);
      for (int k = 0; k < 8; ++k) {
        pair_a.push_back(drive.RenderClean(0));
        drive.SetCommand(0, Twist2{0.3, 0.1});
        drive.Advance(0.1);
        pair_b.push_back(drive.RenderClean(0));
      }
    }
    auto dis = cv::DISOpticalFlow::create(cv::DISOpticalFlow::PRESET_FAST);
    cv::Mat flow;
    j["opencv_dis_fast_320x240_ms"] = MedianMs(args->repeats, 3, [&](int i) {
      const auto k = static_cast<std::size_t>(i) % pair_a.size();
      dis->calc(pair_a[k], pair_b[k], flow);
    });
    j["sim_render_over_dis_fast"] =
        j["sim_render_320x240_ms"].get<double>() / j["opencv_dis_fast_320x240_ms"].get<double>();
    // Issue 4: the paper's dense pyramidal LK (5x5, levels 0-4) against OpenCV's sparse
    // calcOpticalFlowPyrLK asked for every pixel with the same window and levels.
    j["dense_lk_320x240_ms"] = MedianMs(args->repeats, 2, [&](int i) {
      const auto k = static_cast<std::size_t>(i) % pair_a.size();
      flow = flow::DenseLucasKanade(pair_a[k], pair_b[k], flow::DenseLkOptions{});
    });
    {
      std::vector<cv::Point2f> every;
      for (int y = 0; y < pair_a[0].rows; ++y)
        for (int x = 0; x < pair_a[0].cols; ++x) every.emplace_back(x, y);
      std::vector<cv::Point2f> next;
      std::vector<uchar> status;
      std::vector<float> error;
      j["opencv_pyrlk_every_pixel_320x240_ms"] = MedianMs(5, 1, [&](int i) {
        const auto k = static_cast<std::size_t>(i) % pair_a.size();
        cv::calcOpticalFlowPyrLK(pair_a[k], pair_b[k], every, next, status, error, cv::Size(5, 5),
                                 4);
      });
    }
    j["pyrlk_every_pixel_over_dense_lk"] = j["opencv_pyrlk_every_pixel_320x240_ms"].get<double>() /
                                           j["dense_lk_320x240_ms"].get<double>();
    BenchTeachRepeat(&j);
    BenchPotential(args->repeats, &j);
    BenchEigenspace(args->repeats, &j);
    if (args->ros1) BenchMiddleware("ros1", &j);
    if (args->ros2) BenchMiddleware("ros2", &j);
    if (args->fleet) BenchFleet(&j);
    if (args->json) {
      std::cout << j.dump() << "\n";
      return;
    }
    std::printf("%-34s %10s\n", "stage", "median ms");
    for (const char* key : {"sim_render_320x240_ms",
                            "opencv_dis_fast_320x240_ms",
                            "teach_step_ms",
                            "repeat_step_default_ms",
                            "repeat_step_default_mean_ms",
                            "repeat_step_default_p90_ms",
                            "repeat_step_default_with_watch_ms",
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
                            "opencv_pyrlk_every_pixel_320x240_ms",
                            "opencv_dis_fast_ground_320x240_ms",
                            "dominant_plane_step_ms",
                            "dominant_plane_step_dis_medium_ms",
                            "ipca_add_1000_ms",
                            "markov_update_10000_ms",
                            "subwindow_control_ms"}) {
      std::printf("%-34s %10.3f\n", key, j[key].get<double>());
    }
    std::printf("%-34s %10.2f  (issue 2: <= 2.0)\n", "sim_render / dis_fast",
                j["sim_render_over_dis_fast"].get<double>());
    std::printf("%-34s %10.2f  (issue 3: <= 1.5)\n", "repeat_step / orb500",
                j["repeat_step_over_orb"].get<double>());
    std::printf("%-34s %10.2f  (issue 3: <= 1.5; ORB-500 timed after each step)\n",
                "repeat_step / orb500 interl.",
                j["repeat_step_over_orb_interleaved"].get<double>());
    std::printf("%-34s %10.2f  (issue 21: <= 1.5)\n", "repeat_step_default / orb500",
                j["repeat_step_default_over_orb"].get<double>());
    std::printf("%-34s %10.2f  (issue 21: <= 1.5; ORB-500 timed after each step)\n",
                "repeat_step_default / orb500 interl.",
                j["repeat_step_default_over_orb_interleaved"].get<double>());
    std::printf("%-34s %10.2f  (same keypoints and descriptors)\n",
                "orb_detector / opencv same settings",
                j["orb_detector_over_opencv_same_settings"].get<double>());
    std::printf("%-34s %10.2f\n", "repeat_step_default_mean / orb500",
                j["repeat_step_default_mean_over_orb"].get<double>());
    std::printf("%-34s %10.2f  (issue 21: <= 1.0)\n", "obstacle_watch / dis_fast",
                j["obstacle_watch_over_dis_fast"].get<double>());
    std::printf("%-34s %10.2f\n", "repeat_step_fresh / orb500",
                j["repeat_step_fresh_over_orb"].get<double>());
    std::printf("%-34s %10.2f  (issue 3: <= 6.0)\n", "segment_start / orb500",
                j["segment_start_over_orb"].get<double>());
    std::printf("%-34s %10.2f  (issue 4: >= 10)\n", "pyrlk_every_pixel / dense_lk",
                j["pyrlk_every_pixel_over_dense_lk"].get<double>());
    std::printf("%-34s %10.2f  (issue 4: <= 2.0)\n", "dominant_plane_step / dis_fast",
                j["dominant_plane_step_over_dis_fast"].get<double>());
    for (const char* key : {"ipca_add_1000", "markov_update_10000", "subwindow_control"}) {
      std::printf("%-34s %10.2f  (issue 5: <= 1.5)\n", (std::string(key) + " / dis_fast").c_str(),
                  j[std::string(key) + "_over_dis_fast"].get<double>());
    }
    PrintLinkRows(j);
  });
}

}  // namespace mapless::app
