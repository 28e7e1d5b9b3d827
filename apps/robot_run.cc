#include "robot_run.h"

#include <spdlog/spdlog.h>

#include <algorithm>

#include "builtin_middlewares.h"
#include "cli_common.h"
#include "interrupt.h"
#include "mapless/core/check.h"
#include "mapless/robot/robot_file.h"
#include "mapless/run/status_line.h"

namespace mapless::app {

const run::LinkKinds& Links() {
  static const run::LinkKinds kinds = run::StandardLinkKinds(BuiltinMiddlewares());
  return kinds;
}

void SetFollowerRecovery(double carry_on_m, navigation::AppearanceFollowerOptions* follower) {
  follower->carry_on.max_distance_m = carry_on_m;
  if (carry_on_m <= 0.0) follower->recover_images = 0;
}

navigation::ObstacleWatchOptions ObstacleWatchFor(const std::string& robot_path,
                                                  const std::string& on_obstacle,
                                                  const navigation::ObstacleWatchOptions& defaults,
                                                  bool can_avoid) {
  navigation::ObstacleWatchOptions o = defaults;
  std::string from = "--on-obstacle";
  if (!robot_path.empty()) {
    const robot::RobotFile file = robot::LoadRobotFile(robot_path);
    o = file.obstacle;
    if (!file.obstacle_baseline_given) o.baseline_m = defaults.baseline_m;
    if (!file.obstacle_max_unchecked_given) o.max_unchecked_m = defaults.max_unchecked_m;
    from = robot_path + ": obstacles.on_obstacle";
  }
  if (!on_obstacle.empty()) {
    o.enabled = on_obstacle != "off";
    o.avoid = on_obstacle == "avoid";
    from = "--on-obstacle";
  }
  if (o.enabled && o.avoid && !can_avoid)
    throw InputError(from +
                     ": avoid is built for teach & repeat only; the appearance follower stops "
                     "(stop or off)");
  return o;
}

void AddOnObstacleOption(CLI::App* cmd, std::string* on_obstacle, bool can_avoid) {
  cmd->add_option(
         "--on-obstacle", *on_obstacle,
         std::string("Obstacle watch: stop (halt before something new ahead, go on when "
                     "it is gone)") +
             (can_avoid ? ", avoid (go round it by odometry; docs/teach_and_repeat.md)" : "") +
             " or off (the paper's method). Default: the robot file's, else stop")
      ->check(can_avoid ? CLI::IsMember({"stop", "avoid", "off"}) : CLI::IsMember({"stop", "off"}));
}

namespace {

void Say(const std::string& line) { spdlog::info("{}", line); }

// A robot: its robot file's limits, lines when the method holds it, and a failure unless the
// method finished.
void RunOnRobot(robot::Method& method, const std::string& path, const SourceRunArgs& args) {
  const robot::RobotFile file = robot::LoadRobotFile(path);
  std::unique_ptr<JsonLines> log;
  if (!args.log.empty()) log = std::make_unique<JsonLines>(args.log);
  const auto recorder = args.record ? OpenRecorder(*args.record) : nullptr;
  const auto live = OpenLive(args.live, method.name(), false, args.route);
  StopCleanlyOnInterrupt();
  run::LinkRequest request;
  request.method = method.name();
  request.image_size = method.image_size();
  request.warn = [](const std::string& m) { spdlog::warn("{}", m); };
  std::unique_ptr<robot::RobotLink> link = Links().Named("robot").open(path, request);
  spdlog::info("{}: on {} ({}), commands to {}", method.name(), file.name, file.middleware,
               file.Resolve(file.topics.cmd_vel));
  run::StatusLine status;
  run::RunOptions options;
  options.loop = file.Loop();
  options.log = [&log, &status](const nlohmann::json& j) {
    if (log) log->Write(j);
    status.Show(j);
  };
  options.say = [&status](const std::string& line) { status.Clear(), Say(line); };
  options.recorder = recorder.get();
  options.live = live.get();
  const run::RunOutcome outcome = run::RunMethod(method, *link, options);
  link.reset();  // zero velocity published, then off the graph
  status.Clear();
  const bool by_user = !outcome.loop.finished && args.ended_by_user && args.ended_by_user();
  spdlog::info("{}: {} after {} frames: {}", method.name(),
               outcome.loop.finished || by_user ? "finished" : "stopped", outcome.loop.frames,
               by_user ? "ended from the keyboard" : outcome.loop.reason);
  ThrowIfInterrupted();
  if (by_user) return;
  if (!outcome.loop.finished)
    throw RunFailed(std::string(method.name()) + " stopped: " + outcome.loop.reason);
}

// A recording, video, image folder or camera, open loop: the end of the recording is a normal end.
void RunOnRecording(robot::Method& method, const std::string& source, const SourceRunArgs& args) {
  if (args.record && !args.record->path.empty())
    throw InputError("--record: records runs on the simulator or a robot; " + source +
                     " is played open loop (its decisions are in --log)");
  run::LinkRequest request;
  request.method = method.name();
  request.image_size = method.image_size();
  request.size_needed_by = args.size_needed_by;
  request.playback = args.playback;
  std::unique_ptr<robot::RobotLink> link = Links().Open(source, request);
  const auto live = OpenLive(args.live, method.name(), false, args.route);
  JsonLines log(args.log);
  StopCleanlyOnInterrupt();
  run::StatusLine status(!args.log.empty() && args.log != "-");  // not between JSON lines
  run::RunOptions options;
  options.log = [&log, &status](const nlohmann::json& j) { log.Write(j), status.Show(j); };
  options.live = live.get();
  const run::RunOutcome outcome = run::RunMethod(method, *link, options);
  status.Clear();
  ThrowIfInterrupted();
  spdlog::info("{} (open loop on {}): {} frames, {}", method.name(), source, outcome.loop.frames,
               outcome.loop.reason);
  if (!outcome.loop.finished && !outcome.end_of_recording)
    throw RunFailed(std::string(method.name()) + " stopped: " + outcome.loop.reason);
  // A replay on which the method never once drove answered nothing (issue 40: exit 0 with every
  // decision "stopped: needs odometry").
  if (!outcome.loop.finished && outcome.loop.frames > 0 && outcome.driving_frames == 0)
    throw RunFailed(
        std::string(method.name()) + " on " + source + ": stopped on all " +
        std::to_string(outcome.loop.frames) + " frames" +
        (outcome.last_stop_reason.empty() ? "" : ", the last time: " + outcome.last_stop_reason));
}

}  // namespace

void RunOnSource(robot::Method& method, const std::string& source, const SourceRunArgs& args) {
  if (args.robot || Links().For(source).drives) {
    RunOnRobot(method, source, args);
  } else {
    RunOnRecording(method, source, args);
  }
}

run::RunOutcome RunOnSim(robot::Method& method, run::SimRun& sim, const std::string& log_path,
                         recording::RunRecorder* recorder, const robot::LoopObserver& observer,
                         live::LiveView* live) {
  std::unique_ptr<JsonLines> log;
  if (!log_path.empty()) log = std::make_unique<JsonLines>(log_path);
  StopCleanlyOnInterrupt();
  run::RunOptions options;
  if (log) options.log = [&log](const nlohmann::json& j) { log->Write(j); };
  options.more_fields = [&sim](nlohmann::json* j) { sim.AddTruth(j); };
  options.observer = observer;
  options.recorder = recorder;
  options.live = live;
  // A stop that does not clear ends the run as on a robot with the robot file's default
  // (safety.max_blocked_s), not by the simulator's timeout.
  options.loop.max_blocked_s = robot::RobotFile{}.max_blocked_s;
  const run::RunOutcome outcome = run::RunMethod(method, sim.link(), options);
  ThrowIfInterrupted();
  return outcome;
}

}  // namespace mapless::app
