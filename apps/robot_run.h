// Running a method on a robot named by a robot file (`--robot ROBOT.yaml`): opens the robot link of
// the file's middleware, runs the loop (robot/loop.h) until the method is done or the user
// interrupts, logs each decision, and turns the outcome into the exit code.
#pragma once

#include <CLI/CLI.hpp>
#include <memory>
#include <string>

#include "mapless/navigation/appearance.h"
#include "mapless/recording/playback.h"
#include "mapless/recording/run_recorder.h"
#include "mapless/robot/link.h"
#include "mapless/robot/method.h"
#include "mapless/robot/robot_file.h"

namespace mapless::app {

// The robot link of the file's middleware; throws InputError when mapless was built without it.
// `image_size`: frames are resized to it (0x0: as they come).
std::unique_ptr<robot::RobotLink> OpenRobotLink(const robot::RobotFile& robot, cv::Size image_size,
                                                const std::string& method);

// Runs `method` on the robot. Decisions go to `log_path` as JSON lines ("" : none, "-": stdout).
// Throws RunFailed when the method failed or gave up, Interrupted on SIGINT/SIGTERM (after the
// robot was stopped).
// With a recorder, the run is recorded (recording/recording_link.h).
// The obstacle watch of `repeat` and `follow`: the method's `defaults` with the robot file's
// section `obstacles` when a robot file is given (its baseline_m only when the file has one: the
// methods' defaults differ with their speeds), and `on_obstacle` ("stop" or "off"; empty: as
// there; "avoid": go round, teach & repeat only: `can_avoid` false refuses it with one line).
navigation::ObstacleWatchOptions ObstacleWatchFor(const std::string& robot_path,
                                                  const std::string& on_obstacle,
                                                  const navigation::ObstacleWatchOptions& defaults,
                                                  bool can_avoid);
// `follow --carry-on-m`: the follower's recovery of route images and carrying on along the
// leader's odometry at most `carry_on_m` metres; 0 switches both off (the paper's follower).
void SetFollowerRecovery(double carry_on_m, navigation::AppearanceFollowerOptions* follower);
// `--on-obstacle` of `repeat` and `follow` (stop, avoid, off).
void AddOnObstacleOption(CLI::App* cmd, std::string* on_obstacle);

void RunOnRobot(robot::Method& method, const std::string& robot_path, const std::string& log_path,
                recording::RunRecorder* recorder = nullptr);

// Runs `method` open loop on a recording (recording/playback.h) through the same loop as on a
// robot; decisions to `log_path` as JSON lines (robot/status.h). The end of the recording is a
// normal end; throws RunFailed when the method failed, Interrupted on SIGINT/SIGTERM.
void ReplayOnRecording(robot::Method& method, const std::string& source,
                       const recording::PlaybackOptions& playback, const std::string& log_path);

// `mapless sim serve`.
void AddSimServeCommand(CLI::App* sim);

}  // namespace mapless::app
