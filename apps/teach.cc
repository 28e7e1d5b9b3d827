#include "teach.h"

#include <spdlog/spdlog.h>

#include <filesystem>
#include <memory>
#include <optional>

#include "cli_common.h"
#include "interrupt.h"
#include "mapless/core/check.h"
#include "mapless/io/frame_source.h"
#include "mapless/io/output_dir.h"
#include "mapless/recording/recording_link.h"
#include "mapless/robot/link.h"
#include "mapless/robot/robot_file.h"
#include "mapless/run/link_kinds.h"
#include "mapless/run/teach.h"
#include "robot_run.h"

namespace mapless::app {

// Teaching writes the route as it goes into ROUTE (a new or empty directory), or, with
// --overwrite over an existing route, into a staging directory that replaces ROUTE when the teach
// is done (io::OutputDirectory). Ctrl-C ends the teach cleanly: a camera or robot teach ends there
// with a complete route, exit 0 (its normal end); a recording or simulator teach keeps what it
// stored in ROUTE marked incomplete (in place), or leaves the old route untouched (--overwrite),
// exit 130.
void Teach(const TeachArgs& t) {
  const bool eigenspace = t.method == "eigenspace";
  if (!eigenspace && t.method != "funnel")
    throw InputError("--method " + t.method + ": must be funnel or eigenspace");
  if (t.source.empty() == t.robot.empty())
    throw InputError("teach: give one of --source (simulator, recording, camera) or --robot");
  if (!eigenspace) features::ParseDetectorType(t.detector);
  const char* marker = eigenspace ? "appearance.json" : "manifest.json";
  RefuseOutputOverInputs(t.out, "--out", {run::SourceInput(t.source), t.robot});
  RefuseOutputOverInputs(t.record.path, "--record", {run::SourceInput(t.source), t.robot, t.out});
  if (!t.record.path.empty() && !t.source.empty() && !run::IsSim(t.source))
    throw InputError("--record: records teaches on the simulator or a robot; " + t.source +
                     " is already a recording or a camera");
  const std::filesystem::path out_path(t.out);
  if (!t.overwrite && (std::filesystem::exists(out_path / "manifest.json") ||
                       std::filesystem::exists(out_path / "appearance.json"))) {
    throw InputError(t.out +
                     ": already holds a route; choose another directory, or "
                     "--overwrite to replace it");
  }
  if (t.overwrite && !io::IsEmptyOrMissing(t.out) && !std::filesystem::exists(out_path / marker)) {
    // Checked before the source is opened; io::OutputDirectory checks it again.
    throw InputError(t.out + ": holds something else than a route of this kind (no " + marker +
                     "), so --overwrite will not replace it; choose a new or empty directory");
  }
  // The source is opened before anything is written: a bad source changes nothing.
  std::optional<sim::Scenario> scenario;
  std::unique_ptr<robot::RobotLink> link;
  const bool robot = !t.robot.empty();
  bool live = robot;
  int threads = 1;
  if (!robot && run::IsSim(t.source)) {
    scenario = sim::LoadScenario(t.source.substr(4));
  } else {
    run::LinkRequest request;
    request.playback = t.playback;
    request.playback.fps = t.fps;
    request.warn = [](const std::string& m) { spdlog::warn("{}", m); };
    const run::LinkKind& kind = robot ? Links().Named("robot") : Links().For(t.source);
    live = kind.live;
    if (robot) threads = robot::LoadRobotFile(t.robot).threads;  // refused before the output
    link = kind.open(robot ? t.robot : t.source, request);
  }
  const auto recorder = OpenRecorder(
      t.record,
      scenario ? std::optional(recording::CameraInfoOf(scenario->camera.model)) : std::nullopt);
  const auto live_view = OpenLive(t.record.live, "teach", scenario.has_value());  // before output
  io::OutputDirectory out(t.out, t.overwrite, "route", marker);
  StopCleanlyOnInterrupt();
  run::StoreSink store(out.path());
  run::TeacherOptions teacher_options;
  teacher_options.kind = eigenspace ? run::RouteKind::kEigenspace : run::RouteKind::kFunnel;
  teacher_options.detector = t.detector;
  teacher_options.threads = threads;
  // A video or folder without --poses never has odometry; a recording's first frames may come
  // before its first odometry message, as a robot's do.
  teacher_options.never_odometry =
      !robot && !scenario && !live && !recording::IsRecording(t.source) && t.playback.poses.empty();
  run::Teacher teacher(teacher_options, store);
  const run::FrameTap tap =
      run::LiveTeachTap(live_view.get(), teacher,
                        [&](const robot::Observation& f, const std::optional<Pose2>& truth) {
                          if (!recorder) return;
                          if (!f.image.empty()) recorder->Image(f.t_ns, f.image);
                          if (f.odometry) recorder->Odometry(f.t_ns, *f.odometry);
                          if (truth) recorder->GroundTruth(f.t_ns, *truth);
                        });
  run::TeachOutcome outcome;
  try {
    if (scenario) {
      outcome = run::TeachOnSimulator(*scenario, teacher, tap);
    } else {
      if (robot)
        spdlog::info(
            "teach: recording from the robot's camera; drive the robot, Ctrl-C ends the "
            "route");
      outcome = run::TeachFromLink(*link, teacher, tap);
    }
    if (outcome.failed) throw RunFailed("teach: " + outcome.end);
    // Ctrl-C is the end of a camera or robot teach; any other teach it cuts short.
    if (outcome.interrupted && (outcome.frames == 0 || !live)) ThrowIfInterrupted();
  } catch (...) {
    // Bad input, a full disk, a camera gone, an interrupt: a route too short to use is not left
    // behind (it would block the same command's rerun); a longer one stays, and loads as
    // incomplete.
    if (teacher.stored() < teacher.minimum()) out.Discard();
    throw;
  }
  link.reset();
  if (outcome.frames == 0) {
    out.Discard();
    throw InputError((robot ? t.robot : t.source) + ": no frames");
  }
  teacher.Finish();
  if (teacher.deferred_keyframes() > 0)
    spdlog::warn("teach: {} keyframes were deferred for lack of features (a weak stretch)",
                 teacher.deferred_keyframes());
  spdlog::info("teach: {} frames, {} {}", outcome.frames, teacher.stored(), teacher.unit());
  if (teacher.stored() < teacher.minimum()) {
    out.Discard();  // a route too short to use is not left behind to block the next teach
    throw RunFailed("teach: " + std::to_string(teacher.stored()) + " " + teacher.unit() +
                    " (too few features in the images?); a route needs at least " +
                    std::to_string(teacher.minimum()) + ", so none was " +
                    (out.staged() ? "put in place of the old one" : "marked complete"));
  }
  out.Commit();
  spdlog::info(
      "teach: route of {} {} written to {}{}", teacher.stored(), teacher.unit(), t.out,
      outcome.interrupted ? " (ended by Ctrl-C, as a teach on a camera or robot ends)" : "");
}

}  // namespace mapless::app
