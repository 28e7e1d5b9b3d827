// `mapless follow`: the appearance route follower (Payá et al.) on a stored appearance route (from
// `mapless teach --method eigenspace`), on the simulator or on a robot.
#include <spdlog/spdlog.h>

#include "cli_common.h"
#include "fleet.h"
#include "interrupt.h"
#include "mapless/core/check.h"
#include "mapless/recording/playback.h"
#include "mapless/robot/methods.h"
#include "mapless/route/appearance_store.h"
#include "mapless/run/sim_episode.h"
#include "recording_args.h"
#include "robot_run.h"

namespace mapless::app {

namespace {

// The route as the leader that stored it had it: the stored images replayed through the
// incremental PCA (deterministic), complete when the teach finished.
std::shared_ptr<const route::AppearanceRoute> RebuildRoute(const std::string& dir,
                                                           cv::Size* image_size) {
  const route::StoredAppearanceRoute stored = route::LoadAppearanceRoute(dir);
  navigation::AppearanceLeaderOptions options;
  if (stored.low_width != options.image.width || stored.low_height != options.image.height)
    throw InputError(dir + ": route images are " + std::to_string(stored.low_width) + "x" +
                     std::to_string(stored.low_height) + ", this mapless builds its model at " +
                     std::to_string(options.image.width) + "x" +
                     std::to_string(options.image.height));
  if (stored.images.size() < 2)
    throw InputError(dir + ": " + std::to_string(stored.images.size()) +
                     " route images; following needs at least 2");
  navigation::AppearanceLeader leader(options);
  for (const route::StoredAppearanceImage& image : stored.images)
    leader.AddStored(image.low, image.distance_m, image.odometry);
  if (stored.complete) {
    leader.Finish();
  } else {
    spdlog::warn("follow: {} is an interrupted teach; the follower will stop at its end", dir);
  }
  *image_size = cv::Size(stored.image_width, stored.image_height);
  return leader.Snapshot();
}

}  // namespace

void AddFollowCommand(CLI::App* app) {
  struct Args {
    std::string route;
    std::string source;
    std::string robot;
    std::string log;
    std::uint64_t seed = 1;
    double motion_noise = 0.1;
    std::string on_obstacle;  // empty: the robot file's, else stop
    double carry_on_m = navigation::AppearanceFollowerOptions{}.carry_on.max_distance_m;
    FollowConnectArgs fleet;
    RecordArgs record;
    recording::PlaybackOptions playback;
  };
  auto a = std::make_shared<Args>();
  CLI::App* cmd = app->add_subcommand(
      "follow",
      "Follow an appearance route (teach --method eigenspace): initial localization, Markov "
      "localization and sub-window steering, on the simulator or a robot");
  cmd->add_option("--route", a->route,
                  "Appearance route directory; with --connect, where the copy of the leader's "
                  "route is kept (resumed from when it exists)")
      ->required();
  CLI::Option* connect = cmd->add_option(
      "--connect", a->fleet.connect,
      "Follow the route a leader serves (mapless lead --bind), while it is taught: funnel or "
      "eigenspace, as the leader teaches");
  cmd->add_flag("--learn", a->fleet.learn,
                "With --connect, a funnel route: offer the leader the views this repeat learned "
                "(mapless lead --take-views)")
      ->needs(connect);
  cmd->add_option("--real-time-factor", a->fleet.rate,
                  "With --connect on the simulator: simulated seconds per wall-clock second")
      ->capture_default_str()
      ->check(ZeroOrIn(0.01, 100.0));
  AddOldName(cmd, "--rate", "--real-time-factor", &a->fleet.rate)->check(ZeroOrIn(0.01, 100.0));
  cmd->add_option("--summary", a->fleet.summary, "With --connect on the simulator: a JSON summary");
  cmd->add_option("--curve-key", a->fleet.curve_key, "CURVE: this follower's key file");
  cmd->add_option("--curve-leader", a->fleet.curve_leader, "CURVE: the leader's public key file");
  CLI::Option* source = cmd->add_option(
      "--source", a->source, "sim:SCENARIO, or a recording (.mcap, .bag, video, image folder)");
  AddPlaybackOptions(cmd, &a->playback, /*with_rate=*/false);
  AddRecordOptions(cmd, &a->record);
  cmd->add_option("--robot", a->robot, "Drive a robot: its robot file (YAML)")->excludes(source);
  cmd->add_option("--log", a->log, "Per-frame decisions as JSON lines (- for stdout)");
  AddOnObstacleOption(cmd, &a->on_obstacle, false);
  cmd->add_option("--carry-on-m", a->carry_on_m,
                  "Where no route image near the localization fits (the view has changed): try "
                  "the images up to 2 m further on, then drive the leader's odometry at most "
                  "this many metres until one fits (0: neither, the paper's follower; "
                  "docs/appearance_route_following.md, Recovery)")
      ->capture_default_str()
      ->check(FiniteIn(0.0, 100.0));
  cmd->add_option("--seed", a->seed, "Simulator: seed of the motion noise")
      ->capture_default_str()
      ->check(SeedCheck());
  cmd->add_option("--motion-noise", a->motion_noise, "Simulator: fraction of the command")
      ->capture_default_str()
      ->check(FiniteIn(0.0, 0.9));
  cmd->callback([a] {
    if (!a->fleet.connect.empty()) {
      FollowConnectArgs f = a->fleet;
      f.route = a->route;
      f.source = a->source;
      f.robot = a->robot;
      f.log = a->log;
      f.seed = a->seed;
      f.motion_noise = a->motion_noise;
      f.on_obstacle = a->on_obstacle;
      f.carry_on_m = a->carry_on_m;
      f.live = a->record.live;
      RefuseOutputOverInputs(f.log, "--log", {run::SourceInput(f.source), f.robot});
      FollowConnected(f);
      return;
    }
    if (a->source.empty() == a->robot.empty())
      throw InputError("follow: give one of --source sim:SCENARIO or --robot");
    RefuseOutputOverInputs(a->log, "--log", {a->route, run::SourceInput(a->source), a->robot});
    RefuseOutputOverInputs(a->record.path, "--record",
                           {a->route, run::SourceInput(a->source), a->robot});
    // The robot file first: a mistake there is answered before the route's images are read
    // and every one of them goes through the incremental PCA.
    navigation::AppearanceFollowerOptions follower;
    follower.obstacle = ObstacleWatchFor(a->robot, a->on_obstacle, follower.obstacle, false);
    SetFollowerRecovery(a->carry_on_m, &follower);
    cv::Size size;
    const std::shared_ptr<const route::AppearanceRoute> route = RebuildRoute(a->route, &size);
    robot::FollowMethod method([route] { return route; }, follower, size);
    if (!a->robot.empty() || !run::IsSim(a->source)) {
      SourceRunArgs args;
      args.log = a->log;
      args.playback = a->playback;
      args.record = &a->record;
      args.live = a->record.live;
      args.route = live::RoutePoses(*route);
      args.size_needed_by = "the route " + a->route + " was taught at";
      args.robot = !a->robot.empty();
      RunOnSource(method, args.robot ? a->robot : a->source, args);
      return;
    }
    const sim::Scenario scenario = sim::LoadScenario(a->source.substr(4));
    if (scenario.camera.model.width != size.width || scenario.camera.model.height != size.height)
      throw InputError(
          a->source + ": the camera is " + std::to_string(scenario.camera.model.width) + "x" +
          std::to_string(scenario.camera.model.height) + ", the route " + a->route +
          " was taught at " + std::to_string(size.width) + "x" + std::to_string(size.height));
    run::SimRun sim(scenario, run::FollowEpisode(scenario, fleet::RouteKind::kEigenspace, a->seed,
                                                 a->motion_noise, /*live_leader=*/false));
    const auto recorder = OpenRecorder(a->record, recording::CameraInfoOf(scenario.camera.model));
    const auto live = OpenLive(a->record.live, "follow", true, live::RoutePoses(*route));
    const run::RunOutcome outcome = RunOnSim(method, sim, a->log, recorder.get(), {}, live.get());
    spdlog::info("follow: {} ({} frames); {:.2f} m from the route's end", outcome.loop.reason,
                 outcome.loop.frames, sim.error_at_end_m());
    if (!sim.succeeded(outcome.loop.finished))
      throw RunFailed("follow did not succeed: " + outcome.loop.reason);
  });
}

}  // namespace mapless::app
