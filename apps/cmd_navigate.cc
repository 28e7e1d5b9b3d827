// `mapless navigate`: visual-potential navigation (Ohnishi & Imiya) on the simulator — corridor
// centring, a destination, or a destination and home — with the per-frame decisions as JSON lines.
#include <spdlog/spdlog.h>

#include <nlohmann/json.hpp>

#include "cli_common.h"
#include "interrupt.h"
#include "mapless/core/check.h"
#include "mapless/eval/potential.h"
#include "mapless/io/atomic_file.h"
#include "mapless/io/limits.h"
#include "mapless/recording/recording_link.h"
#include "mapless/robot/methods.h"
#include "mapless/robot/robot_file.h"
#include "mapless/run/decision_log.h"
#include "recording_args.h"
#include "robot_run.h"

namespace mapless::app {
namespace {

// How far beyond the scenario's objects, path and destinations a start or a destination may lie.
constexpr double kNavigationMarginM = 5.0;

}  // namespace

namespace {
struct NavigateArgs {
  std::string scenario;
  std::string destination;
  int destination_index = -1;
  bool homing = false;
  std::string start;
  std::string calibration;
  std::string save_calibration;
  std::string log;
  std::uint64_t seed = 1;
  double motion_noise = 0.1;
  double image_noise = 2.0;
  std::string robot;
  RecordArgs record;
};

// `navigate --robot`: the visual potential on a robot through its robot link.
void NavigateOnRobot(const NavigateArgs& a, bool by_index) {
  RefuseOutputOverInputs(a.log, "--log", {a.robot, a.calibration});
  if (a.calibration.empty())
    throw InputError(
        "navigate --robot needs --calibration FILE (the planar-flow calibration: "
        "`mapless navigate --scenario S --save-calibration FILE` on the simulator)");
  const navigation::PlanarFlowCalibration calibration = navigation::CalibrationFromYaml(
      io::ReadFile(a.calibration, io::kMaxYamlFileBytes), a.calibration);
  std::optional<Eigen::Vector2d> destination;
  if (!a.destination.empty() && by_index)
    throw InputError("--destination and --destination-index: give one of them");
  if (!a.destination.empty()) {
    const std::vector<double> d = ParseNumbers(a.destination, "--destination", 2, "X,Y");
    if (std::hypot(d[0], d[1]) > 1000.0)
      throw InputError("--destination " + a.destination + ": more than 1 km away");
    destination = Eigen::Vector2d(d[0], d[1]);
  } else if (by_index) {
    if (a.scenario.empty()) throw InputError("--destination-index needs --scenario");
    const sim::Scenario scenario = sim::LoadScenario(a.scenario);
    if (a.destination_index < 0 ||
        a.destination_index >= static_cast<int>(scenario.destinations.size()))
      throw InputError("--destination-index " + std::to_string(a.destination_index) +
                       ": scenario " + scenario.name + " has " +
                       std::to_string(scenario.destinations.size()) + " destinations");
    destination = scenario.destinations[static_cast<std::size_t>(a.destination_index)];
  }
  if (a.homing && !destination) throw InputError("--homing needs a destination");
  navigation::PotentialNavOptions nav;
  nav.homing = a.homing;
  nav.flow.threads = robot::LoadRobotFile(a.robot).threads;  // the same flow on any number
  robot::PotentialMethod method(calibration, nav, destination);
  RefuseOutputOverInputs(a.record.path, "--record", {a.robot, a.calibration});
  SourceRunArgs args;
  args.log = a.log;
  args.record = &a.record;
  args.robot = true;
  RunOnSource(method, a.robot, args);
}

// `navigate --scenario`: the suite's run of the visual potential on the simulator (calibrated by
// driving first, or from --calibration), its decisions logged in the run layer's one format.
void NavigateOnSim(const NavigateArgs& a, bool by_index) {
  if (a.scenario.empty()) throw InputError("navigate: give --scenario (simulator) or --robot");
  RefuseOutputOverInputs(a.log, "--log", {a.scenario, a.calibration});
  RefuseOutputOverInputs(a.save_calibration, "--save-calibration",
                         {a.scenario, a.calibration, a.log});
  if (by_index && a.destination_index < 0) {
    throw InputError("--destination-index " + std::to_string(a.destination_index) +
                     ": must be 0 or more");
  }
  sim::Scenario scenario = sim::LoadScenario(a.scenario);
  // The robot must start, and its goal lie, where the world is: the scenario's area (objects,
  // taught path, starts and destinations) with a margin. Outside it there is nothing to see.
  const Eigen::Vector4d area = sim::ScenarioBounds(scenario, kNavigationMarginM);
  const auto in_area = [&](double x, double y) {
    return x >= area[0] && y >= area[1] && x <= area[2] && y <= area[3];
  };
  const std::string area_text =
      fmt::format("[{:.1f}, {:.1f}] x [{:.1f}, {:.1f}] m", area[0], area[2], area[1], area[3]);
  if (!a.start.empty()) {
    scenario.teach_start = ParsePoseDeg(a.start, "--start-pose");
    if (!in_area(scenario.teach_start.x_m, scenario.teach_start.y_m))
      throw InputError("--start-pose " + a.start + ": outside the scenario's area " + area_text);
  }
  eval::PotentialRunOptions o;
  o.seed = a.seed;
  o.motion_noise_frac = a.motion_noise;
  o.image_noise_sigma = a.image_noise;
  o.homing = a.homing;
  if (!a.destination.empty() && a.destination_index >= 0)
    throw InputError("--destination and --destination-index: give one of them");
  if (!a.destination.empty()) {
    const std::vector<double> d = ParseNumbers(a.destination, "--destination", 2, "X,Y");
    if (!in_area(d[0], d[1]))
      throw InputError("--destination " + a.destination + ": outside the scenario's area " +
                       area_text);
    o.destination = Eigen::Vector2d(d[0], d[1]);
  } else if (a.destination_index >= 0) {
    if (a.destination_index >= static_cast<int>(scenario.destinations.size()))
      throw InputError("--destination-index " + std::to_string(a.destination_index) +
                       ": scenario " + scenario.name + " has " +
                       std::to_string(scenario.destinations.size()) + " destinations");
    o.destination = scenario.destinations[static_cast<std::size_t>(a.destination_index)];
  }
  if (o.homing && !o.destination) throw InputError("--homing needs a destination");

  navigation::PlanarFlowCalibration calibration;
  if (!a.calibration.empty()) {
    calibration = navigation::CalibrationFromYaml(
        io::ReadFile(a.calibration, io::kMaxYamlFileBytes), a.calibration);
    if (calibration.width != scenario.camera.model.width ||
        calibration.height != scenario.camera.model.height)
      throw InputError(a.calibration + ": calibrated for " + std::to_string(calibration.width) +
                       "x" + std::to_string(calibration.height) + ", the camera is " +
                       std::to_string(scenario.camera.model.width) + "x" +
                       std::to_string(scenario.camera.model.height));
  } else {
    spdlog::info("navigate: calibrating the planar flows (straight at T_m, then turning)");
    calibration = eval::CalibrateOnSimulator(scenario, o.nav);
  }
  if (!a.save_calibration.empty())
    io::WriteFileAtomic(a.save_calibration, navigation::CalibrationToYaml(calibration));

  RefuseOutputOverInputs(a.record.path, "--record", {a.calibration, a.scenario});
  const auto recorder = OpenRecorder(a.record, recording::CameraInfoOf(scenario.camera.model));
  const auto live = OpenLive(a.record.live, "navigate", true);
  std::unique_ptr<JsonLines> log;
  if (!a.log.empty()) log = std::make_unique<JsonLines>(a.log);
  o.wrap_link = run::LogDecisions(
      "navigate", log ? run::JsonSink([&log](const nlohmann::json& j) { log->Write(j); }) : nullptr,
      RecordingWrapper(recorder.get(), "navigate", live.get()));
  StopCleanlyOnInterrupt();
  const eval::PotentialRun run = eval::RunPotential(
      scenario, calibration, o,
      [](const Pose2&, const cv::Mat&, const navigation::PotentialStep&) { ThrowIfInterrupted(); });
  spdlog::info("navigate: {} after {:.1f} s ({} frames){}", run.status, run.duration_s,
               run.path.size(),
               o.destination ? fmt::format(", {:.2f} m from the goal", run.final_error_m) : "");
  if (!run.success) throw RunFailed("navigate: " + run.status);
}

}  // namespace

void AddNavigateCommand(CLI::App* app) {
  using Args = NavigateArgs;
  auto a = std::make_shared<Args>();
  CLI::App* cmd = app->add_subcommand(
      "navigate",
      "Visual-potential navigation on the simulator: free ground from optical flow, obstacles "
      "avoided, a destination reached (and home again with --homing)");
  cmd->add_option("--scenario", a->scenario,
                  "Built-in scenario name or scenario YAML file (with --robot: only to look up "
                  "--destination-index)");
  cmd->add_option("--robot", a->robot,
                  "Drive a robot: its robot file (YAML). Needs --calibration; --destination is "
                  "then in the odometry frame (REP-105 odom), metres");
  cmd->add_option("--destination", a->destination,
                  "X,Y in the world (metres); without one the robot drives ahead and keeps to "
                  "the middle of free space until it passes the end of the taught path");
  cmd->add_option("--destination-index", a->destination_index,
                  "Use the scenario's destination number N (0-based)");
  cmd->add_flag("--homing", a->homing, "At the destination turn round and come back");
  cmd->add_option("--start-pose", a->start, "X,Y,THETA_DEG (default: the scenario's teach start)");
  AddOldName(cmd, "--start", "--start-pose", &a->start);
  cmd->add_option("--calibration", a->calibration,
                  "Planar-flow calibration file to use (default: calibrate by driving first)");
  cmd->add_option("--save-calibration", a->save_calibration,
                  "Write the calibration used to this file (YAML)");
  cmd->add_option("--log", a->log, "Per-frame decisions as JSON lines (- for stdout)");
  AddRecordOptions(cmd, &a->record);
  cmd->add_option("--seed", a->seed, "Noise seed")->capture_default_str()->check(SeedCheck());
  cmd->add_option("--motion-noise", a->motion_noise, "Fraction of T and R")
      ->capture_default_str()
      ->check(FiniteIn(0.0, 0.9));
  cmd->add_option("--image-noise", a->image_noise, "Gaussian image noise, grey levels")
      ->capture_default_str()
      ->check(FiniteIn(0.0, 100.0));
  cmd->callback([a, cmd] {
    const bool by_index = cmd->count("--destination-index") > 0;
    if (!a->robot.empty()) {
      NavigateOnRobot(*a, by_index);
    } else {
      NavigateOnSim(*a, by_index);
    }
  });
}

}  // namespace mapless::app
