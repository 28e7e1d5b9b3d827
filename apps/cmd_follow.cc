// `mapless follow`: the appearance route follower (Payá et al.) on a stored appearance route (from
// `mapless teach --method eigenspace`), on the simulator or on a robot.
#include <spdlog/spdlog.h>

#include "cli_common.h"
#include "fleet.h"
#include "interrupt.h"
#include "mapless/core/check.h"
#include "mapless/eval/eigenspace.h"
#include "mapless/recording/playback.h"
#include "mapless/recording/recording_link.h"
#include "mapless/robot/loop.h"
#include "mapless/robot/methods.h"
#include "mapless/robot/sim_link.h"
#include "mapless/robot/status.h"
#include "mapless/route/appearance_store.h"
#include "mapless/sim/driver.h"
#include "recording_args.h"
#include "robot_run.h"
#include "teach.h"

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

void ReplayOnRecording(robot::Method& method, const std::string& source,
                       const recording::PlaybackOptions& playback, const std::string& log_path) {
  recording::PlaybackLink link(recording::OpenSource(source, playback));
  JsonLines log(log_path);
  StopCleanlyOnInterrupt();
  int frame = 0;
  int decided = 0;  // frames on which the method could decide (it drove, or chose to wait)
  std::string why_not;
  const robot::LoopResult result = robot::RunLoop(
      method, link, robot::LoopOptions{},
      [&](const robot::Observation& obs, const robot::Decision& decision) {
        log.Write(robot::StatusJson(method.name(), frame++, obs, decision));
        if (decision.state == robot::MethodState::kDriving) ++decided;
        if (decision.state != robot::MethodState::kDriving && !decision.reason.empty())
          why_not = decision.reason;
        return true;
      },
      [] { return InterruptSignal() != 0; });
  ThrowIfInterrupted();
  spdlog::info("{} (open loop on {}): {} frames, {}", method.name(), source, result.frames,
               result.reason);
  if (!result.finished && result.reason != recording::kEndOfRecording)
    throw RunFailed(std::string(method.name()) + " stopped: " + result.reason);
  // A replay on which the method never once drove answered nothing (issue 40: exit 0 with every
  // decision "stopped: needs odometry").
  if (!result.finished && result.frames > 0 && decided == 0)
    throw RunFailed(std::string(method.name()) + " on " + source + ": stopped on all " +
                    std::to_string(result.frames) + " frames" +
                    (why_not.empty() ? "" : ", the last time: " + why_not));
}

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
  cmd->add_option("--connect", a->fleet.connect,
                  "Follow the route a leader serves (mapless lead --bind), while it is taught: "
                  "funnel or eigenspace, as the leader teaches");
  cmd->add_option("--rate", a->fleet.rate,
                  "With --connect on the simulator: simulated seconds per wall-clock second")
      ->capture_default_str()
      ->check(ZeroOrIn(0.01, 100.0));
  cmd->add_option("--summary", a->fleet.summary, "With --connect on the simulator: a JSON summary");
  cmd->add_option("--curve-key", a->fleet.curve_key, "CURVE: this follower's key file");
  cmd->add_option("--curve-leader", a->fleet.curve_leader, "CURVE: the leader's public key file");
  CLI::Option* source = cmd->add_option(
      "--source", a->source, "sim:SCENARIO, or a recording (.mcap, .bag, video, image folder)");
  AddPlaybackOptions(cmd, &a->playback, /*with_rate=*/false);
  AddRecordOptions(cmd, &a->record);
  cmd->add_option("--robot", a->robot, "Drive a robot: its robot file (YAML)")->excludes(source);
  cmd->add_option("--log", a->log, "Per-frame decisions as JSON lines (- for stdout)");
  AddOnObstacleOption(cmd, &a->on_obstacle);
  cmd->add_option("--carry-on-m", a->carry_on_m,
                  "Where no route image near the localization fits (the view has changed): try "
                  "the images up to 2 m further on, then drive the leader's odometry at most "
                  "this many metres until one fits (0: neither, the paper's follower; "
                  "docs/appearance_route_following.md#recovery-where-the-route-images-no-longer-"
                  "fit-issue-21-not-in-the-paper)")
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
      RefuseOutputOverInputs(f.log, "--log", {SourceInput(f.source), f.robot});
      FollowConnected(f);
      return;
    }
    if (a->source.empty() == a->robot.empty())
      throw InputError("follow: give one of --source sim:SCENARIO or --robot");
    RefuseOutputOverInputs(a->log, "--log", {a->route, SourceInput(a->source), a->robot});
    RefuseOutputOverInputs(a->record.path, "--record",
                           {a->route, SourceInput(a->source), a->robot});
    cv::Size size;
    const std::shared_ptr<const route::AppearanceRoute> route = RebuildRoute(a->route, &size);
    navigation::AppearanceFollowerOptions follower;
    follower.obstacle = ObstacleWatchFor(a->robot, a->on_obstacle, follower.obstacle, false);
    SetFollowerRecovery(a->carry_on_m, &follower);
    robot::FollowMethod method([route] { return route; }, follower, size);
    if (!a->robot.empty()) {
      const auto recorder = OpenRecorder(a->record);
      RunOnRobot(method, a->robot, a->log, recorder.get());
      return;
    }
    if (!IsSim(a->source)) {
      if (!a->record.path.empty())
        throw InputError("--record: records runs on the simulator or a robot; " + a->source +
                         " is played open loop (its decisions are in --log)");
      ReplayOnRecording(method, a->source, a->playback, a->log);
      return;
    }
    const sim::Scenario scenario = sim::LoadScenario(a->source.substr(4));
    if (scenario.camera.model.width != size.width || scenario.camera.model.height != size.height)
      throw InputError(
          a->source + ": the camera is " + std::to_string(scenario.camera.model.width) + "x" +
          std::to_string(scenario.camera.model.height) + ", the route " + a->route +
          " was taught at " + std::to_string(size.width) + "x" + std::to_string(size.height));
    eval::EigenspaceRunOptions options;
    options.seed = a->seed;
    options.motion_noise = a->motion_noise;
    const eval::SimSetup setup = eval::FollowSimSetup(scenario, options);
    sim::Simulation sim(setup.world, setup.camera, {}, setup.seed);
    const int r = sim.AddRobot(setup.start, setup.robot);
    robot::SimLinkOptions link_options;
    link_options.period_s = 1.0 / scenario.camera.rate_hz;
    link_options.timeout_s = eval::FollowTimeoutS(scenario, options);
    robot::SimLink link(sim, r, link_options);
    const auto recorder = OpenRecorder(a->record, recording::CameraInfoOf(scenario.camera.model));
    const robot::LinkWrapper wrap = RecordingWrapper(recorder.get(), method.name());
    const std::unique_ptr<robot::RobotLink> wrapped = wrap ? wrap(link) : nullptr;
    JsonLines log(a->log);
    StopCleanlyOnInterrupt();
    int frame = 0;
    const robot::LoopResult result = robot::RunLoop(
        method, wrapped ? *wrapped : static_cast<robot::RobotLink&>(link), robot::LoopOptions{},
        [&](const robot::Observation& obs, const robot::Decision& decision) {
          ThrowIfInterrupted();
          nlohmann::json j = robot::StatusJson(method.name(), frame++, obs, decision);
          j["x_m"] = link.truth().x_m;
          j["y_m"] = link.truth().y_m;
          j["theta_rad"] = link.truth().theta_rad;
          if (!a->log.empty()) log.Write(j);
          return true;
        });
    // The taught path's end (drawn without rendering) is where the follower should arrive.
    Pose2 end = scenario.teach_start;
    sim::DriveOptions drive;
    drive.render_frames = false;
    sim::DriveTaughtPath(scenario, drive, [&](const sim::DriveFrame& f) { end = f.truth; });
    const double error = link.truth().DistanceTo(end);
    spdlog::info("follow: {} ({} frames); {:.2f} m from the route's end", result.reason,
                 result.frames, error);
    if (!result.finished || sim.collided(r) || error > options.arrive_tolerance_m)
      throw RunFailed("follow did not succeed: " + result.reason);
  });
}

}  // namespace mapless::app
