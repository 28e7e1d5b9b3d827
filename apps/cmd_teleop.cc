// `mapless teleop --robot ROBOT.yaml`: drive a robot from this terminal's keyboard (robot/teleop.h)
#include <spdlog/spdlog.h>

#include "mapless/core/interrupt.h"
#include "mapless/robot/teleop.h"
#include "mapless/run/keyboard.h"
#include "robot_run.h"

namespace mapless::app {

void AddTeleopCommand(CLI::App* app) {
  struct Args {
    std::string robot;
    robot::TeleopOptions keys;
  };
  auto a = std::make_shared<Args>();
  CLI::App* cmd = app->add_subcommand(
      "teleop", "Drive a robot from the keyboard, to teach a route: keys here, cmd_vel out");
  cmd->add_option("--robot", a->robot, "The robot file (YAML): middleware, topics, speed limits")
      ->required();
  cmd->add_option("--speed-fraction", a->keys.speed_fraction,
                  "Starting speed, a fraction of the robot file's limits (+ and - change it)")
      ->capture_default_str();
  cmd->add_option("--hold", a->keys.hold_s, "Seconds a key drives after its last repeat")
      ->capture_default_str();
  cmd->callback([a] {
    const robot::RobotFile file = robot::LoadRobotFile(a->robot);
    a->keys.max_speed_mps = file.max_speed_mps;
    a->keys.max_turn_rate_radps = file.max_turn_rate_radps;
    // Whatever ends the keys ends the run at once, camera frames or not: every wait of the robot
    // link hears the request within milliseconds, and the robot gets a zero Twist.
    run::Keyboard keyboard(0, [] { RequestInterrupt(); });
    robot::TeleopMethod method(a->keys, [&keyboard] { return keyboard.Read(); });
    spdlog::info("teleop: {}", robot::TeleopKeysHelp());
    SourceRunArgs args;
    args.robot = true;
    args.ended_by_user = [&keyboard] { return keyboard.ended(); };
    RunOnSource(method, a->robot, args);
  });
}

}  // namespace mapless::app
