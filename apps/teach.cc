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
#include "mapless/navigation/appearance.h"
#include "mapless/navigation/teach.h"
#include "mapless/recording/recording_link.h"
#include "mapless/robot/link.h"
#include "mapless/robot/robot_file.h"
#include "mapless/route/appearance_store.h"
#include "mapless/route/route_store.h"
#include "robot_run.h"

namespace mapless::app {

bool IsSim(const std::string& source) { return source.rfind("sim:", 0) == 0; }

std::string SourceInput(const std::string& source) {
  if (IsSim(source)) {
    const std::string name = source.substr(4);
    return name.find('/') != std::string::npos || name.find(".y") != std::string::npos ? name : "";
  }
  return source.rfind("camera:", 0) == 0 ? "" : source;
}

namespace {

// What a teach makes from frames: keyframes (funnel lanes) or appearance route images.
class Teacher {
 public:
  virtual ~Teacher() = default;
  virtual void Frame(const cv::Mat& image, Timestamp t_ns,
                     const std::optional<Pose2>& odometry) = 0;
  virtual void Finish() = 0;  // marks the route complete
  virtual int stored() const = 0;
  virtual int minimum() const = 0;  // a route needs at least this many
  virtual const char* unit() const = 0;
};

class KeyframeTeacher : public Teacher {
 public:
  KeyframeTeacher(std::string dir, const std::string& detector)
      : dir_(std::move(dir)), detector_(detector) {
    options_.features.type = features::ParseDetectorType(detector);
    options_.Validate();
    session_ = std::make_unique<navigation::TeachSession>(options_);
  }
  void Frame(const cv::Mat& image, Timestamp t_ns, const std::optional<Pose2>& odometry) override {
    if (!writer_)
      writer_ = std::make_unique<route::RouteWriter>(dir_, detector_, image.cols, image.rows);
    Keep(session_->Update(image, t_ns, odometry));
  }
  void Finish() override {
    if (!writer_) return;
    Keep(session_->Finish());
    if (session_->deferred_keyframes() > 0)
      spdlog::warn("teach: {} keyframes were deferred for lack of features (a weak stretch)",
                   session_->deferred_keyframes());
    if (stored() >= minimum()) writer_->Finish();
  }
  int stored() const override { return stored_; }
  int minimum() const override { return 2; }
  const char* unit() const override { return "keyframes"; }

 private:
  void Keep(const std::optional<route::Keyframe>& kf) {
    if (!kf) return;
    writer_->Append(*kf);
    ++stored_;
  }
  std::string dir_;
  std::string detector_;
  navigation::TeachOptions options_;
  std::unique_ptr<navigation::TeachSession> session_;
  std::unique_ptr<route::RouteWriter> writer_;
  int stored_ = 0;
};

class AppearanceTeacher : public Teacher {
 public:
  // `no_odometry_source`: the source never has odometry (a recording): refuse at once.
  AppearanceTeacher(std::string dir, bool no_odometry_source)
      : dir_(std::move(dir)), no_odometry_source_(no_odometry_source) {}
  void Frame(const cv::Mat& image, Timestamp, const std::optional<Pose2>& odometry) override {
    if (!odometry) {
      // A robot's first frames may come before its first odometry message: skip them, but not
      // for ever.
      if (++without_odometry_ < 30 && !no_odometry_source_) return;
      throw InputError(
          "teach --method eigenspace needs wheel odometry (route images are spaced "
          "by distance): teach on sim:SCENARIO, on a robot or a recording with an odometry "
          "topic, or on a video or image folder with --poses FILE.tum");
    }
    if (!writer_) {
      writer_ = std::make_unique<route::AppearanceRouteWriter>(
          dir_, image.cols, image.rows, options_.image.width, options_.image.height);
    }
    if (leader_.Update(image, *odometry)) {
      writer_->Append({leader_.last_low(), leader_.distance_m(), *odometry});
    }
  }
  void Finish() override {
    if (writer_ && stored() >= minimum()) writer_->Finish();
  }
  int stored() const override { return writer_ ? writer_->images() : 0; }
  int minimum() const override { return 2; }
  const char* unit() const override { return "route images"; }

 private:
  std::string dir_;
  navigation::AppearanceLeaderOptions options_;
  navigation::AppearanceLeader leader_{options_};
  std::unique_ptr<route::AppearanceRouteWriter> writer_;
  bool no_odometry_source_ = false;
  int without_odometry_ = 0;
};

}  // namespace

// Teaching writes the route as it goes into ROUTE (a new or empty directory), or, with
// --overwrite over an existing route, into a staging directory that replaces ROUTE when the teach
// is done (io::OutputDirectory). Ctrl-C ends the teach cleanly: a camera or robot teach ends there
// with a complete route; a recording or simulator teach keeps what it stored in ROUTE marked
// incomplete (in place), or leaves the old route untouched (--overwrite).
void Teach(const TeachArgs& t) {
  const bool eigenspace = t.method == "eigenspace";
  if (!eigenspace && t.method != "funnel")
    throw InputError("--method " + t.method + ": must be funnel or eigenspace");
  if (t.source.empty() == t.robot.empty())
    throw InputError("teach: give one of --source (simulator, recording, camera) or --robot");
  if (!eigenspace) features::ParseDetectorType(t.detector);
  const char* marker = eigenspace ? "appearance.json" : "manifest.json";
  RefuseOutputOverInputs(t.out, "--out", {SourceInput(t.source), t.robot});
  RefuseOutputOverInputs(t.record.path, "--record", {SourceInput(t.source), t.robot, t.out});
  if (!t.record.path.empty() && !t.source.empty() && !IsSim(t.source))
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
  std::unique_ptr<io::FrameSource> source;
  std::optional<robot::RobotFile> robot_file;
  if (!t.robot.empty()) {
    robot_file = robot::LoadRobotFile(t.robot);
  } else if (IsSim(t.source)) {
    scenario = sim::LoadScenario(t.source.substr(4));
  } else {
    recording::PlaybackOptions playback = t.playback;
    playback.fps = t.fps;
    source = recording::OpenSource(t.source, playback);
  }
  const auto recorder = OpenRecorder(
      t.record,
      scenario ? std::optional(recording::CameraInfoOf(scenario->camera.model)) : std::nullopt);
  io::OutputDirectory out(t.out, t.overwrite, "route", marker);
  StopCleanlyOnInterrupt();
  std::unique_ptr<Teacher> teacher;
  if (eigenspace) {
    // A video or folder without --poses never has odometry; a recording's first frames may come
    // before its first odometry message, as a robot's do.
    const bool never_odometry =
        source != nullptr && !recording::IsRecording(t.source) && t.playback.poses.empty();
    teacher = std::make_unique<AppearanceTeacher>(out.path(), never_odometry);
  } else {
    teacher = std::make_unique<KeyframeTeacher>(out.path(), t.detector);
  }
  int frames = 0;
  const auto frame_in = [&](const cv::Mat& image, Timestamp t_ns,
                            const std::optional<Pose2>& odometry,
                            const std::optional<Pose2>& truth = std::nullopt) {
    ThrowIfInterrupted();
    if (recorder) {
      if (!image.empty()) recorder->Image(t_ns, image);
      if (odometry) recorder->Odometry(t_ns, *odometry);
      if (truth) recorder->GroundTruth(t_ns, *truth);
    }
    teacher->Frame(image, t_ns, odometry);
    ++frames;
  };
  bool interrupted = false;
  try {
    if (scenario) {
      const sim::DriveSummary summary = sim::DriveTaughtPath(
          *scenario, sim::DriveOptions{},
          [&](const sim::DriveFrame& f) { frame_in(f.image, f.t_ns, f.odometry, f.truth); });
      if (!summary.completed) {
        throw RunFailed("teach: the drive of '" + scenario->name +
                        "' did not complete: " + summary.status);
      }
    } else if (robot_file) {
      // A person drives; mapless only records (it never publishes a command while teaching).
      std::unique_ptr<robot::RobotLink> link = OpenRobotLink(*robot_file, {}, "teach");
      spdlog::info("teach: recording from {}; drive the robot, Ctrl-C ends the route",
                   robot_file->Resolve(robot_file->topics.compressed_image.empty()
                                           ? robot_file->topics.image
                                           : robot_file->topics.compressed_image));
      while (true) {
        ThrowIfInterrupted();
        robot::LinkEvent e = link->Next();
        if (e.type == robot::LinkEventType::kClosed) {
          ThrowIfInterrupted();  // the link heard the interrupt first
          throw RunFailed("teach: " + e.reason);
        }
        if (e.type != robot::LinkEventType::kFrame) continue;
        frame_in(e.observation.image, e.observation.t_ns, e.observation.odometry);
      }
    } else {
      io::Frame frame;
      while (source->Next(&frame)) frame_in(frame.image, frame.t_ns, frame.odometry);
    }
  } catch (const Interrupted&) {
    if (frames == 0 || !(io::IsLiveCamera(t.source) || robot_file)) {
      if (teacher->stored() < teacher->minimum()) out.Discard();
      throw;
    }
    interrupted = true;  // the end of a camera or robot teach
  } catch (...) {
    // Bad input, a full disk, a camera gone: a route too short to use is not left behind (it
    // would block the same command's rerun); a longer one stays, and loads as incomplete.
    if (teacher->stored() < teacher->minimum()) out.Discard();
    throw;
  }
  if (frames == 0) {
    out.Discard();
    throw InputError((robot_file ? t.robot : t.source) + ": no frames");
  }
  teacher->Finish();
  spdlog::info("teach: {} frames, {} {}", frames, teacher->stored(), teacher->unit());
  if (teacher->stored() < teacher->minimum()) {
    out.Discard();  // a route too short to use is not left behind to block the next teach
    throw RunFailed("teach: " + std::to_string(teacher->stored()) + " " + teacher->unit() +
                    " (too few features in the images?); a route needs at least " +
                    std::to_string(teacher->minimum()) + ", so none was " +
                    (out.staged() ? "put in place of the old one" : "marked complete"));
  }
  out.Commit();
  spdlog::info("teach: route of {} {} written to {}", teacher->stored(), teacher->unit(), t.out);
  if (interrupted) throw Interrupted(InterruptSignal());
}

}  // namespace mapless::app
