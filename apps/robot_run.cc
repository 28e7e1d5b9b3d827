#include "robot_run.h"

#include <spdlog/spdlog.h>

#include <algorithm>

#include "builtin_middlewares.h"
#include "cli_common.h"
#include "interrupt.h"
#include "mapless/core/check.h"
#include "mapless/recording/recording_link.h"
#include "mapless/robot/loop.h"
#include "mapless/robot/status.h"

namespace mapless::app {

std::unique_ptr<robot::RobotLink> OpenRobotLink(const robot::RobotFile& robot, cv::Size image_size,
                                                const std::string& method) {
  return BuiltinMiddlewares().For(robot).open_link(
      robot, image_size, method, [](const std::string& m) { spdlog::warn("{}", m); });
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

void AddOnObstacleOption(CLI::App* cmd, std::string* on_obstacle) {
  cmd->add_option("--on-obstacle", *on_obstacle,
                  "Obstacle watch: stop (halt before something new on the way ahead, status "
                  "blocked or stopped with the reason, go on when it is gone), avoid (teach & "
                  "repeat: go round it by odometry and rejoin the route; "
                  "docs/teach_and_repeat.md#avoid) or off (the paper's method). Default: the "
                  "robot file's obstacles.on_obstacle, else stop "
                  "(docs/teach_and_repeat.md#obstacle-watch)")
      ->check(CLI::IsMember({"stop", "avoid", "off"}));
}

void RunOnRobot(robot::Method& method, const std::string& robot_path, const std::string& log_path,
                recording::RunRecorder* recorder) {
  const robot::RobotFile file = robot::LoadRobotFile(robot_path);
  std::unique_ptr<JsonLines> log;
  if (!log_path.empty()) log = std::make_unique<JsonLines>(log_path);
  StopCleanlyOnInterrupt();
  std::unique_ptr<robot::RobotLink> link = OpenRobotLink(file, method.image_size(), method.name());
  std::unique_ptr<robot::RobotLink> recording;
  if (recorder)
    recording = std::make_unique<recording::RecordingLink>(*link, *recorder, method.name());
  spdlog::info("{}: on {} ({}), commands to {}", method.name(), file.name, file.middleware,
               file.Resolve(file.topics.cmd_vel));
  int frame = 0;
  std::string last_state;
  const robot::LoopResult result = robot::RunLoop(
      method, recording ? *recording : *link, file.Loop(),
      [&](const robot::Observation& obs, const robot::Decision& decision) {
        if (log) log->Write(robot::StatusJson(method.name(), frame, obs, decision));
        ++frame;
        const std::string state =
            decision.status + (decision.reason.empty() ? "" : ": " + decision.reason);
        if (decision.state != robot::MethodState::kDriving && state != last_state)
          spdlog::info("{}: {}", method.name(), state);
        last_state = decision.state == robot::MethodState::kDriving ? "" : state;
        return true;
      },
      [] { return InterruptSignal() != 0; });
  recording.reset();
  link.reset();  // zero velocity published, then off the graph
  spdlog::info("{}: {} after {} frames: {}", method.name(),
               result.finished ? "finished" : "stopped", result.frames, result.reason);
  ThrowIfInterrupted();
  if (!result.finished) throw RunFailed(std::string(method.name()) + " stopped: " + result.reason);
}

}  // namespace mapless::app
