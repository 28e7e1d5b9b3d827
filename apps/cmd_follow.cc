// `mapless follow`: the appearance route follower (Payá et al.) on a stored appearance route (from
// `mapless teach --method eigenspace`), on the simulator or on a robot.
#include <spdlog/spdlog.h>

#include "cli_common.h"
#include "fleet.h"
#include "interrupt.h"
#include "mapless/core/check.h"
#include "mapless/io/output_dir.h"
#include "mapless/navigation/appearance_experiences.h"
#include "mapless/recording/playback.h"
#include "mapless/robot/methods.h"
#include "mapless/route/appearance_store.h"
#include "mapless/run/learn.h"
#include "mapless/run/sim_episode.h"
#include "recording_args.h"
#include "robot_run.h"

namespace mapless::app {

namespace {

// The route as the leader that stored it had it: the stored images replayed through the
// incremental PCA (deterministic), then the views follows learned into it, complete when the
// teach finished.
std::shared_ptr<const route::AppearanceRoute> RebuildRoute(
    const std::string& dir, const route::StoredAppearanceRoute& stored, cv::Size* image_size) {
  if (stored.images.size() < 2)
    throw InputError(dir + ": " + std::to_string(stored.images.size()) +
                     " route images; following needs at least 2");
  if (!stored.complete)
    spdlog::warn("follow: {} is an interrupted teach; the follower will stop at its end", dir);
  *image_size = cv::Size(stored.image_width, stored.image_height);
  try {
    return navigation::BuildStoredAppearanceRoute(stored, navigation::AppearanceLeaderOptions{});
  } catch (const InputError& e) {
    throw InputError(dir + ": " + e.what());
  }
}

// `follow --learn`: the views the follow learned, written into its route when it arrived.
void SaveLearned(const std::string& dir, const route::StoredAppearanceRoute& stored,
                 const robot::FollowMethod& method,
                 const navigation::AppearanceFollowerOptions& options) {
  spdlog::info("follow: {}",
               run::SaveAppearanceVisit(dir, stored, method.follower().used_views(),
                                        method.follower().learned(), options.experiences));
}

// `mapless follow`'s options.
struct FollowArgs {
  std::string route;
  std::string source;
  std::string robot;
  std::string log;
  std::uint64_t seed = 1;
  double motion_noise = 0.1;
  std::string on_obstacle;  // empty: the robot file's, else stop
  bool learn = false;
  double carry_on_m = navigation::AppearanceFollowerOptions{}.carry_on.max_distance_m;
  FollowConnectArgs fleet;
  RecordArgs record;
  recording::PlaybackOptions playback;
};

// `mapless follow --route DIR` on the simulator, a recording or a robot (not --connect).
void FollowStored(const FollowArgs& a) {
  if (a.source.empty() == a.robot.empty())
    throw InputError("follow: give one of --source sim:SCENARIO or --robot");
  RefuseOutputOverInputs(a.log, "--log", {a.route, run::SourceInput(a.source), a.robot});
  RefuseOutputOverInputs(a.record.path, "--record", {a.route, run::SourceInput(a.source), a.robot});
  // The robot file first: a mistake there is answered before the route's images are read
  // and every one of them goes through the incremental PCA.
  navigation::AppearanceFollowerOptions follower;
  follower.obstacle = ObstacleWatchFor(a.robot, a.on_obstacle, follower.obstacle, false);
  SetFollowerRecovery(a.carry_on_m, &follower);
  follower.learn = a.learn;
  // --learn writes into the route: no other process may write it meanwhile.
  const auto lock = a.learn ? std::make_unique<io::DirectoryLock>(a.route) : nullptr;
  const route::StoredAppearanceRoute stored = route::LoadAppearanceRoute(a.route);
  if (a.learn)
    run::CheckLearnable(a.route, stored.complete, stored.visits, "views", "follow --learn");
  cv::Size size;
  const std::shared_ptr<const route::AppearanceRoute> route = RebuildRoute(a.route, stored, &size);
  robot::FollowMethod method([route] { return route; }, follower, size);
  if (!a.robot.empty() || !run::IsSim(a.source)) {
    SourceRunArgs source;
    source.log = a.log;
    source.playback = a.playback;
    source.record = &a.record;
    source.live = a.record.live;
    source.route = live::RoutePoses(*route);
    source.size_needed_by = "the route " + a.route + " was taught at";
    source.robot = !a.robot.empty();
    RunOnSource(method, source.robot ? a.robot : a.source, source);
    if (a.learn) SaveLearned(a.route, stored, method, follower);
    return;
  }
  const sim::Scenario scenario = sim::LoadScenario(a.source.substr(4));
  if (scenario.camera.model.width != size.width || scenario.camera.model.height != size.height)
    throw InputError(a.source + ": the camera is " + std::to_string(scenario.camera.model.width) +
                     "x" + std::to_string(scenario.camera.model.height) + ", the route " + a.route +
                     " was taught at " + std::to_string(size.width) + "x" +
                     std::to_string(size.height));
  run::SimRun sim(scenario, run::FollowEpisode(scenario, fleet::RouteKind::kEigenspace, a.seed,
                                               a.motion_noise, /*live_leader=*/false));
  const auto recorder = OpenRecorder(a.record, recording::CameraInfoOf(scenario.camera.model));
  const auto live = OpenLive(a.record.live, "follow", true, live::RoutePoses(*route));
  const run::RunOutcome outcome = RunOnSim(method, sim, a.log, recorder.get(), {}, live.get());
  spdlog::info("follow: {} ({} frames); {:.2f} m from the route's end", outcome.loop.reason,
               outcome.loop.frames, sim.error_at_end_m());
  if (!sim.succeeded(outcome.loop.finished))
    throw RunFailed("follow did not succeed: " + outcome.loop.reason);
  if (a.learn) SaveLearned(a.route, stored, method, follower);
}

}  // namespace

void AddFollowCommand(CLI::App* app) {
  auto a = std::make_shared<FollowArgs>();
  CLI::App* cmd = app->add_subcommand(
      "follow",
      "Follow an appearance route (teach --method eigenspace): initial localization, Markov "
      "localization and sub-window steering, on the simulator or a robot");
  cmd->add_option("--route", a->route,
                  "Appearance route directory; with --connect, where the copy of the leader's "
                  "route is kept (resumed from when it exists)")
      ->required();
  cmd->add_option(
      "--connect", a->fleet.connect,
      "Follow the route a leader serves (mapless lead --bind), while it is taught: funnel or "
      "eigenspace, as the leader teaches");
  cmd->add_flag("--learn", a->learn,
                "Learn views of the places whose appearance has changed and write them into the "
                "(complete) route when the follow arrives (docs/appearance_route_following.md, "
                "Experiences); with --connect, a funnel route: offer the leader the views this "
                "repeat learned (mapless lead --take-views)");
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
      f.learn = a->learn;
      RefuseOutputOverInputs(f.log, "--log", {run::SourceInput(f.source), f.robot});
      FollowConnected(f);
      return;
    }
    FollowStored(*a);
  });
}

}  // namespace mapless::app
