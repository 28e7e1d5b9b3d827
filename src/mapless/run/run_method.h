// Running a method on a link: the one loop (robot/loop.h) with its safety rules, and around it
// what every run of a command has: the recording of the run, the decision log, a line when the
// method's state changes, the user's interrupt, and the outcome in a form the command can report.
// Every command that runs a method (repeat, navigate, follow, follow --connect, on a robot, on a
// recording or on the simulator) comes here.
#pragma once

#include <functional>
#include <nlohmann/json.hpp>
#include <string>

#include "mapless/live/live_view.h"
#include "mapless/recording/run_recorder.h"
#include "mapless/robot/link.h"
#include "mapless/robot/loop.h"
#include "mapless/robot/method.h"

namespace mapless::run {

struct RunOptions {
  robot::LoopOptions loop;  // speed limits, stale frames, giving up without frames
  // Each decision as one JSON object (robot/status.h), with `more_fields` added; empty: none.
  std::function<void(const nlohmann::json&)> log;
  std::function<void(nlohmann::json*)> more_fields;  // e.g. the simulator's true pose
  // Said when the method's state or reason changes while it does not drive, and at the end
  // (the robot's owner sees why it stopped); empty: silent.
  std::function<void(const std::string&)> say;
  // Called on every decision after it was logged; false ends the run there as finished (an
  // evaluation's own goal).
  robot::LoopObserver observer;
  // The run is recorded into this recorder (recording/recording_link.h); null: not recorded.
  recording::RunRecorder* recorder = nullptr;
  // The run is shown live (live/live_view.h: --live); null: not shown.
  live::LiveView* live = nullptr;
  // Checked at every frame and while waiting; by default the process-wide interrupt
  // (core/interrupt.h: Ctrl-C, SIGTERM).
  std::function<bool()> interrupted;
};

struct RunOutcome {
  robot::LoopResult loop;        // finished or not, the reason, frames
  int driving_frames = 0;        // frames on which the method drove
  std::string last_stop_reason;  // why the method last held the robot (empty: it never did)
  bool interrupted = false;
  // The recording ended (a recording's normal end: the method was not done but nothing failed).
  bool end_of_recording = false;
};

RunOutcome RunMethod(robot::Method& method, robot::RobotLink& link, const RunOptions& options);

}  // namespace mapless::run
