// `mapless teach`, `mapless repeat`, `mapless route info`: visual teach & repeat with the funnel
// lanes on the simulator (closed loop) or on recorded sources (open loop, decisions as JSON lines).
#include <spdlog/spdlog.h>

#include <cstdio>
#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>

#include "cli_common.h"
#include "interrupt.h"
#include "mapless/core/check.h"
#include "mapless/eval/teach_repeat.h"
#include "mapless/io/frame_source.h"
#include "mapless/io/output_dir.h"
#include "mapless/recording/recording_link.h"
#include "mapless/robot/methods.h"
#include "mapless/robot/robot_file.h"
#include "mapless/route/appearance_store.h"
#include "mapless/route/route_store.h"
#include "mapless/run/decision_log.h"
#include "mapless/run/learn.h"
#include "mapless/run/link_kinds.h"
#include "mapless/run/route_info.h"
#include "mapless/run/sim_episode.h"
#include "recording_args.h"
#include "robot_run.h"
#include "teach.h"

namespace mapless::app {
namespace {

struct RepeatArgs : SwitchingArgs {
  std::string route;
  std::string source;
  std::string controller = "sloped";
  std::string on_obstacle;  // empty: the robot file's, else stop
  std::string log;
  std::uint64_t seed = 1;
  double motion_noise = 0.1;
  double image_noise = 2.0;
  double fps = 10.0;
  std::string robot;
  double speed = 0.2;
  bool learn = false;
  RecordArgs record;
  recording::PlaybackOptions playback;
};

// `repeat --source sim:SCENARIO`: one run of the suite's repeat (eval::RepeatOnSimulator) on the
// route, its decisions logged in the one format of the run layer.
void RepeatOnSim(const RepeatArgs& r, const std::shared_ptr<route::Route>& route,
                 const navigation::RepeatOptions& options) {
  const sim::Scenario scenario = sim::LoadScenario(r.source.substr(4));
  if (scenario.camera.model.width != route->image_width ||
      scenario.camera.model.height != route->image_height) {
    throw InputError(r.source + ": the camera is " + std::to_string(scenario.camera.model.width) +
                     "x" + std::to_string(scenario.camera.model.height) + ", the route " + r.route +
                     " was taught at " + std::to_string(route->image_width) + "x" +
                     std::to_string(route->image_height));
  }
  const auto recorder = OpenRecorder(r.record, recording::CameraInfoOf(scenario.camera.model));
  const auto live = OpenLive(r.record.live, "repeat", true, live::RoutePoses(*route));
  JsonLines log(r.log);
  StopCleanlyOnInterrupt();
  const run::SimEpisode episode = run::FollowEpisode(scenario, fleet::RouteKind::kFunnel, r.seed,
                                                     r.motion_noise, /*live_leader=*/false);
  eval::TaughtRoute taught;
  taught.route = route;
  taught.path = episode.taught;
  taught.duration_s = episode.taught_duration_s;
  eval::RepeatRunOptions run_options;
  run_options.repeat = options;
  run_options.seed = r.seed;
  run_options.motion_noise_frac = r.motion_noise;
  run_options.image_noise_sigma = r.image_noise;
  run_options.wrap_link = run::LogDecisions(
      "repeat", [&log](const nlohmann::json& j) { log.Write(j); },
      RecordingWrapper(recorder.get(), "repeat", live.get()));
  const double speed = eval::RepeatSpeedFor(scenario, run_options.max_repeat_speed_mps);
  run_options.repeat.sloped.max_speed_mps = speed;
  run_options.repeat.standard.forward_speed_mps = speed;
  const eval::RepeatRun run = eval::RepeatOnSimulator(
      scenario, taught, run_options,
      [&](const Pose2&, const cv::Mat&, const navigation::RepeatStep&) { ThrowIfInterrupted(); });
  spdlog::info("repeat: {} ({}): {}; final error {:.2f} m, lateral RMS {:.2f} m, {:.1f} s",
               scenario.name, r.controller, run.status, run.final_error_m, run.lateral_rms_m,
               run.duration_s);
  if (!run.success) throw RunFailed("repeat did not succeed: " + run.status);
  if (r.learn)
    spdlog::info("repeat: {}",
                 run::SaveVisit(r.route, *route, run.used_views, run.learned, options.experiences));
}

// `mapless repeat`: the funnel-lane repeat on a robot, a recording or the simulator.
void Repeat(const RepeatArgs& r) {
  if (r.source.empty() && r.robot.empty())
    throw InputError("repeat: give --source (simulator, recording, camera) or --robot");
  RefuseOutputOverInputs(r.log, "--log", {r.route, run::SourceInput(r.source), r.robot});
  RefuseOutputOverInputs(r.record.path, "--record", {r.route, run::SourceInput(r.source), r.robot});
  if (!r.record.path.empty() && !r.source.empty() && !run::IsSim(r.source))
    throw InputError("--record: records runs on the simulator or a robot; " + r.source +
                     " is played open loop (its decisions are in --log)");
  // The robot file first: it is read in milliseconds, a route's keyframe images take longer.
  const int robot_threads = r.robot.empty() ? 0 : robot::LoadRobotFile(r.robot).threads;
  // --learn writes into the route: no other process may write it meanwhile.
  const auto lock = r.learn ? std::make_unique<io::DirectoryLock>(r.route) : nullptr;
  auto route = std::make_shared<route::Route>(route::LoadRoute(r.route));
  if (r.learn)
    run::CheckLearnable(r.route, route->complete, route->visits, "keyframes", "repeat --learn");
  if (!route->complete)
    spdlog::warn("repeat: {} is an interrupted teach; repeating its {} keyframes", r.route,
                 route->keyframes.size());
  navigation::RepeatOptions options;
  options.controller = navigation::ParseController(r.controller);
  r.ApplyTo(&options);
  options.features.type = features::ParseDetectorType(route->detector);
  options.obstacle = ObstacleWatchFor(r.robot, r.on_obstacle, options.obstacle, true);
  options.learn = r.learn;
  if (!r.robot.empty() || !run::IsSim(r.source)) {
    if (!r.robot.empty()) {
      options.threads = robot_threads;
      options.sloped.max_speed_mps = r.speed;
      options.standard.forward_speed_mps = r.speed;
    }
    robot::RepeatMethod method(route, options);
    SourceRunArgs args;
    args.log = r.log;
    args.playback = r.playback;
    args.playback.fps = r.fps;
    args.record = &r.record;
    args.live = r.record.live;
    args.route = live::RoutePoses(*route);
    args.size_needed_by = "the route " + r.route + " was taught at";
    args.robot = !r.robot.empty();
    RunOnSource(method, args.robot ? r.robot : r.source, args);
    if (r.learn && method.session())
      spdlog::info("repeat: {}",
                   run::SaveVisit(r.route, *route, method.session()->used_views(),
                                  method.session()->TakeLearned(), options.experiences));
    return;
  }
  RepeatOnSim(r, route, options);
}

}  // namespace

static void AddTeachCommand(CLI::App* app) {
  auto t = std::make_shared<TeachArgs>();
  CLI::App* teach = app->add_subcommand(
      "teach",
      "Teach a route: keyframes from a video, an image folder, a camera or sim:SCENARIO. Ctrl-C "
      "ends a camera or robot teach with a complete route (exit 0); any other it stops cleanly "
      "(exit 130), its finished keyframes kept, marked incomplete");
  CLI::Option* teach_source = teach->add_option(
      "--source", t->source, "sim:SCENARIO, a video file, an image folder, camera:N");
  teach
      ->add_option("--robot", t->robot,
                   "Teach on a robot (its robot file): a person drives it (teleop on cmd_vel), "
                   "mapless records from the camera topic until Ctrl-C")
      ->excludes(teach_source);
  teach
      ->add_option("--method", t->method,
                   "funnel (keyframes, for `repeat`) or eigenspace (appearance route images, "
                   "for `follow`)")
      ->capture_default_str();
  teach->add_option("--out", t->out, "Route directory to create")->required();
  teach->add_flag("--overwrite", t->overwrite,
                  "Replace a route already in --out (the old one stays until the new one is done)");
  teach->add_option("--detector", t->detector, "orb, akaze, akaze_upright or sift")
      ->capture_default_str();
  teach->add_option("--fps", t->fps, "Frame rate of image folders (timestamps)")
      ->capture_default_str()
      ->check(FiniteIn(io::kMinFolderFps, io::kMaxFolderFps));
  AddPlaybackOptions(teach, &t->playback);
  AddRecordOptions(teach, &t->record);
  teach->callback([t] { Teach(*t); });
}

static void AddRepeatCommand(CLI::App* app) {
  auto r = std::make_shared<RepeatArgs>();
  CLI::App* repeat = app->add_subcommand(
      "repeat",
      "Repeat a taught route: drive the simulator, or decide frame by frame on a recording");
  repeat->add_option("--route", r->route, "Route directory (from mapless teach)")->required();
  CLI::Option* source_opt = repeat->add_option(
      "--source", r->source, "sim:SCENARIO, a video file, an image folder, camera:N");
  repeat
      ->add_option("--robot", r->robot,
                   "Drive a robot: its robot file (YAML: middleware, topics, limits)")
      ->excludes(source_opt);
  repeat
      ->add_option("--speed", r->speed,
                   "Robot: forward speed of the funnel lanes, m/s (the simulator uses the "
                   "scenario's teach speed, at most 0.2)")
      ->capture_default_str()
      ->check(FiniteIn(0.01, 5.0));
  repeat->add_option("--controller", r->controller, "sloped or standard")->capture_default_str();
  repeat->add_flag("--learn", r->learn,
                   "Learn how the route's places look today: views of keyframes whose appearance "
                   "changed, written into the route when the repeat ends");
  AddSwitchingOptions(repeat, r.get());
  AddOnObstacleOption(repeat, &r->on_obstacle, true);
  repeat->add_option("--log", r->log,
                     "Per-frame decisions as JSON lines to this file (default: stdout; on a robot: "
                     "none, - for stdout)");
  repeat->add_option("--seed", r->seed, "Simulator: seed of the noise")
      ->capture_default_str()
      ->check(SeedCheck());
  repeat->add_option("--motion-noise", r->motion_noise, "Simulator: fraction of the command")
      ->capture_default_str()
      ->check(FiniteIn(0.0, 0.9));
  repeat->add_option("--image-noise", r->image_noise, "Simulator: grey levels")
      ->capture_default_str()
      ->check(FiniteIn(0.0, 100.0));
  repeat->add_option("--fps", r->fps, "Frame rate of image folders (timestamps)")
      ->capture_default_str()
      ->check(FiniteIn(io::kMinFolderFps, io::kMaxFolderFps));
  AddPlaybackOptions(repeat, &r->playback);
  AddRecordOptions(repeat, &r->record);
  repeat->callback([r] { Repeat(*r); });
}

static void AddRouteCommand(CLI::App* app) {
  CLI::App* route_cmd = app->add_subcommand("route", "Inspect a taught route");
  route_cmd->require_subcommand(1);
  struct Args {
    std::string route, other;
    bool json = false, views = false;
    int max_views = 5;
  };
  auto a = std::make_shared<Args>();
  CLI::App* info =
      route_cmd->add_subcommand("info", "Load a route (checking every file) and describe it");
  info->add_option("ROUTE", a->route, "Route directory")->required();
  info->add_flag("--json", a->json, "Print one JSON object");
  info->add_flag("--views", a->views,
                 "List each keyframe's (repeat --learn) or route image's (follow --learn) learned "
                 "views");
  info->callback([a] {
    const nlohmann::json j = run::RouteInfo(a->route, a->views);
    std::cout << (a->json ? j.dump() : run::RouteInfoLine(a->route, j)) << "\n";
  });
  CLI::App* prune = route_cmd->add_subcommand(
      "prune",
      "Keep at most N views per keyframe (or route image of an appearance route), dropping the "
      "learned views used least recently");
  CLI::App* merge = route_cmd->add_subcommand(
      "merge", "Add the views another copy of the route learned (repeat --learn elsewhere)");
  for (CLI::App* c : {prune, merge}) {
    c->add_option("ROUTE", a->route, "Route directory")->required();
    if (c == merge) c->add_option("OTHER", a->other, "The other copy (only read)")->required();
    c->add_option("--max-views", a->max_views, "Views per place, the taught one included")
        ->capture_default_str()
        ->check(CLI::Range(1, 64));
  }
  prune->callback([a] { std::cout << run::PruneRouteViews(a->route, a->max_views) << "\n"; });
  merge->callback(
      [a] { std::cout << run::MergeRouteViews(a->route, a->other, a->max_views) << "\n"; });
}

void AddTeachRepeatCommands(CLI::App* app) {
  AddTeachCommand(app);
  AddRepeatCommand(app);
  AddRouteCommand(app);
}

}  // namespace mapless::app
