// The commands' side of the run layer (src/mapless/run): a method's run on a robot, a recording or
// the simulator with the command line's conventions (the log, the lines said, the exit code), and
// the options that several commands share.
#pragma once

#include <CLI/CLI.hpp>
#include <functional>
#include <memory>
#include <string>

#include "mapless/navigation/appearance.h"
#include "mapless/recording/playback.h"
#include "mapless/recording/run_recorder.h"
#include "mapless/robot/link.h"
#include "mapless/robot/method.h"
#include "mapless/robot/robot_file.h"
#include "mapless/run/link_kinds.h"
#include "mapless/run/run_method.h"
#include "mapless/run/sim_episode.h"
#include "recording_args.h"

namespace mapless::app {

// The link kinds of this build (run/link_kinds.h): robot files over the middlewares built in,
// cameras and recordings.
const run::LinkKinds& Links();

// How a command runs a method on a source that is not the simulator.
struct SourceRunArgs {
  // Decisions as JSON lines to this file; "-": stdout; "": none on a robot, stdout otherwise.
  std::string log;
  recording::PlaybackOptions playback;  // a recording, video, folder or camera
  const RecordArgs* record = nullptr;   // --record: a robot's run is recorded
  live::LiveArgs live;                  // --live: the run shown live
  std::vector<Pose2> route;             // the taught route in its odometry frame, for the live view
  std::string size_needed_by;  // "the route R was taught at": a recording's frames must match
  bool robot = false;          // the source is a robot file (--robot), whatever its name
  // The user ended the run at the method's own input, between frames too (teleop's keyboard:
  // Ctrl-C or Ctrl-D, or its end). The loop then ends at once (mapless::RequestInterrupt) with
  // the robot stopped, and the run counts as finished, not failed.
  std::function<bool()> ended_by_user;
};

// Runs `method` on `source` (a robot file, a camera or a recording; run/link_kinds.h) through the
// run layer (run/run_method.h). On a robot: the loop limits of its robot file, a line when the
// method holds the robot and why, RunFailed when the method failed or gave up. On a recording: the
// end of the recording is a normal end, but a method that never once drove answered nothing
// (RunFailed). Interrupted on SIGINT/SIGTERM (after the robot was stopped).
void RunOnSource(robot::Method& method, const std::string& source, const SourceRunArgs& args);

// Runs `method` on the simulator (run/sim_episode.h), decisions with the true pose to `log`
// ("": none, "-": stdout), recorded with `record`, shown in `live`; `observer` sees every decision.
run::RunOutcome RunOnSim(robot::Method& method, run::SimRun& sim, const std::string& log,
                         recording::RunRecorder* recorder, const robot::LoopObserver& observer = {},
                         live::LiveView* live = nullptr);

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
// --on-obstacle; `can_avoid`: avoid is offered (teach & repeat), else stop and off only.
void AddOnObstacleOption(CLI::App* cmd, std::string* on_obstacle, bool can_avoid);

// `mapless sim serve`.
void AddSimServeCommand(CLI::App* sim);

}  // namespace mapless::app
