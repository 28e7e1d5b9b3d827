// The method stages of `mapless bench` (bench.h): the renderer, the flows, then each method's own
// stages (teach_repeat.cc and below), each next to a stock OpenCV primitive of the same run.
#include <algorithm>
#include <chrono>
#include <functional>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/video/tracking.hpp>
#include <sstream>

#include "mapless/appearance/image.h"
#include "mapless/appearance/pca.h"
#include "mapless/appearance/subwindow.h"
#include "mapless/bench/bench.h"
#include "mapless/bench/timing.h"
#include "mapless/control/subwindow_steering.h"
#include "mapless/core/check.h"
#include "mapless/eval/potential.h"
#include "mapless/eval/teach_repeat.h"
#include "mapless/flow/flow.h"
#include "mapless/localization/markov.h"

namespace mapless::bench {

// The middleware's robot-link latency rows (bench_links.cc).

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
  auto time_step = [&](flow::FlowMethod method, int threads = 1) {
    navigation::PotentialNavOptions o = nav;
    o.flow.method = method;
    o.flow.threads = threads;
    if (method == flow::FlowMethod::kDisFast) o.flow.dis_max_flow_width_px = 0;  // the preset's
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
  (*j)["navigator_default_over_dis_fast"] =
      (*j)["dominant_plane_step_dis_medium_ms"].get<double>() /
      (*j)["opencv_dis_fast_ground_320x240_ms"].get<double>();
  // As `navigate --robot` runs it with a robot file's `threads: 2` (the same flow).
  (*j)["dominant_plane_step_dis_medium_2_threads_ms"] = time_step(flow::FlowMethod::kDisMedium, 2);
  (*j)["navigator_default_2_threads_over_dis_fast"] =
      (*j)["dominant_plane_step_dis_medium_2_threads_ms"].get<double>() /
      (*j)["opencv_dis_fast_ground_320x240_ms"].get<double>();
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

nlohmann::json BenchStages(const StageOptions& options) {
  if (options.frame.area() > 0) BenchFrameSize() = options.frame;
  cv::setNumThreads(1);
  const std::vector<std::string> names =
      options.scenarios.empty()
          ? std::vector<std::string>{"narrow_room_sharp_turn", "outdoor_70m", "office_aliasing"}
          : options.scenarios;
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
    scenario.camera.model =
        sim::CameraModel::FromFov(BenchFrameSize().width, BenchFrameSize().height, DegToRad(60.0));
    renderers.push_back(std::make_unique<sim::Renderer>(scenario.world, sim::RenderOptions{}));
    for (const Pose2& p : sim::PosesAlongTaughtPath(scenario, 12))
      views.push_back({renderers.back().get(), scenario.camera, p});
  }
  const sim::Scenario scenario = BenchScenario(names.front());

  nlohmann::json j;
  j["scenarios"] = names;
  j["threads"] = cv::getNumThreads();
  j["frame"] =
      std::to_string(BenchFrameSize().width) + "x" + std::to_string(BenchFrameSize().height);
  j["repeats"] = options.repeats;
  cv::Mat sink;
  // The renderer's kernels in use (AVX2 where the CPU has it), then the baseline build of them
  // on the same views: the same images, the time a CPU without AVX2 would take relative to DIS.
  j["sim_render_kernels"] = sim::RenderKernels();
  auto render = [&](int i) {
    const View& v = views[static_cast<std::size_t>(i) % views.size()];
    sink = v.renderer->Render(v.camera.model, sim::WorldFromCamera(v.pose, v.camera.mount));
  };
  j["sim_render_320x240_ms"] = MedianMs(options.repeats, 3, render);
  sim::UseBaselineRenderKernels(true);
  j["sim_render_baseline_kernels_320x240_ms"] = MedianMs(options.repeats, 3, render);
  sim::UseBaselineRenderKernels(false);
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
  j["opencv_dis_fast_320x240_ms"] = MedianMs(options.repeats, 3, [&](int i) {
    const auto k = static_cast<std::size_t>(i) % pair_a.size();
    dis->calc(pair_a[k], pair_b[k], flow);
  });
  j["sim_render_over_dis_fast"] =
      j["sim_render_320x240_ms"].get<double>() / j["opencv_dis_fast_320x240_ms"].get<double>();
  j["sim_render_baseline_kernels_over_dis_fast"] =
      j["sim_render_baseline_kernels_320x240_ms"].get<double>() /
      j["opencv_dis_fast_320x240_ms"].get<double>();
  // Issue 4: the paper's dense pyramidal LK (5x5, levels 0-4) against OpenCV's sparse
  // calcOpticalFlowPyrLK asked for every pixel with the same window and levels.
  // Its vector loops in use (AVX2 where the CPU has it), then their baseline build: the same flow.
  j["dense_lk_kernels"] = flow::DenseLkKernels();
  const auto dense_lk = [&](int i) {
    const auto k = static_cast<std::size_t>(i) % pair_a.size();
    flow = flow::DenseLucasKanade(pair_a[k], pair_b[k], flow::DenseLkOptions{});
  };
  j["dense_lk_320x240_ms"] = MedianMs(options.repeats, 2, dense_lk);
  flow::UseBaselineDenseLkKernels(true);
  j["dense_lk_baseline_kernels_320x240_ms"] = MedianMs(options.repeats, 2, dense_lk);
  flow::UseBaselineDenseLkKernels(false);
  {
    std::vector<cv::Point2f> every;
    for (int y = 0; y < pair_a[0].rows; ++y)
      for (int x = 0; x < pair_a[0].cols; ++x) every.emplace_back(x, y);
    std::vector<cv::Point2f> next;
    std::vector<uchar> status;
    std::vector<float> error;
    j["opencv_pyrlk_every_pixel_320x240_ms"] = MedianMs(9, 1, [&](int i) {
      const auto k = static_cast<std::size_t>(i) % pair_a.size();
      cv::calcOpticalFlowPyrLK(pair_a[k], pair_b[k], every, next, status, error, cv::Size(5, 5), 4);
    });
  }
  j["pyrlk_every_pixel_over_dense_lk"] = j["opencv_pyrlk_every_pixel_320x240_ms"].get<double>() /
                                         j["dense_lk_320x240_ms"].get<double>();
  j["pyrlk_every_pixel_over_dense_lk_baseline_kernels"] =
      j["opencv_pyrlk_every_pixel_320x240_ms"].get<double>() /
      j["dense_lk_baseline_kernels_320x240_ms"].get<double>();
  BenchTeachRepeat(&j);
  BenchPotential(options.repeats, &j);
  BenchEigenspace(options.repeats, &j);
  BenchRealImageStages(options.repeats, &j);
  return j;
}

}  // namespace mapless::bench
