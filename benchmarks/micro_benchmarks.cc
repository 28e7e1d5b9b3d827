// Google Benchmark micro benchmarks. The per-stage medians users quote come from `mapless bench`;
// these are for profiling single primitives while optimising.
#include <benchmark/benchmark.h>

#include <opencv2/core.hpp>
#include <opencv2/video/tracking.hpp>

#include "mapless/sim/simulation.h"

namespace {

using mapless::Pose2;
using mapless::Twist2;
using mapless::sim::LoadScenario;
using mapless::sim::Simulation;

void RenderLoop(benchmark::State& state, const char* scenario_name, const Pose2& pose) {
  cv::setNumThreads(1);
  const auto scenario = LoadScenario(scenario_name);
  Simulation sim(scenario.world, scenario.camera, {}, 1);
  sim.AddRobot(pose, scenario.robot);
  for (auto _ : state) benchmark::DoNotOptimize(sim.RenderClean(0).data);
}

void BM_SimRender320x240(benchmark::State& state) {
  RenderLoop(state, "narrow_room_sharp_turn", Pose2{1.0, 0.0, 0.0});
}
BENCHMARK(BM_SimRender320x240)->Unit(benchmark::kMillisecond);

void BM_SimRenderOutdoor320x240(benchmark::State& state) {
  RenderLoop(state, "outdoor_70m", Pose2{10.0, 0.0, 0.0});
}
BENCHMARK(BM_SimRenderOutdoor320x240)->Unit(benchmark::kMillisecond);

void BM_OpenCvDisFast320x240(benchmark::State& state) {
  cv::setNumThreads(1);
  const auto scenario = LoadScenario("narrow_room_sharp_turn");
  Simulation sim(scenario.world, scenario.camera, {}, 1);
  sim.AddRobot(Pose2{1.0, 0.0, 0.0}, scenario.robot);
  const cv::Mat a = sim.RenderClean(0);
  sim.SetCommand(0, Twist2{0.3, 0.1});
  sim.Advance(0.1);
  const cv::Mat b = sim.RenderClean(0);
  auto dis = cv::DISOpticalFlow::create(cv::DISOpticalFlow::PRESET_FAST);
  cv::Mat flow;
  for (auto _ : state) dis->calc(a, b, flow);
}
BENCHMARK(BM_OpenCvDisFast320x240)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
