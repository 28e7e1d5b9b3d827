// Teaching through one teach loop: frames from any link (a robot a person drives, a camera, a
// recording) or from the simulator's scripted drive go to one teacher, which makes the route
// (funnel-lane keyframes, or appearance route images) and hands each piece to a route sink: the
// route store on disk (`mapless teach`), a fleet leader that serves it while it is taught
// (`mapless lead`, leader_sink.h), or both (TeeSink).
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "mapless/fleet/route_log.h"
#include "mapless/live/live_view.h"
#include "mapless/navigation/appearance.h"
#include "mapless/navigation/teach.h"
#include "mapless/robot/link.h"
#include "mapless/route/appearance_store.h"
#include "mapless/route/route.h"
#include "mapless/sim/simulation.h"

namespace mapless::run {

using fleet::RouteKind;
// "funnel" or "eigenspace" (the teach's --method); throws InputError naming the value.
RouteKind ParseTeachMethod(const std::string& text);

// What the route is, known at its first frame: the fleet's header record says the same.
using RouteStart = fleet::RouteHeader;

// Where a route goes as it is taught.
class RouteSink {
 public:
  virtual ~RouteSink() = default;
  virtual void Start(const RouteStart& start) = 0;
  virtual void Keyframe(const route::Keyframe& keyframe) = 0;
  virtual void Image(const route::StoredAppearanceImage& image) = 0;
  virtual void Finish() = 0;  // the route is complete
};

// The route store (route/route_store.h, route/appearance_store.h) in DIR.
class StoreSink : public RouteSink {
 public:
  explicit StoreSink(std::string dir);
  ~StoreSink() override;
  void Start(const RouteStart& start) override;
  void Keyframe(const route::Keyframe& keyframe) override;
  void Image(const route::StoredAppearanceImage& image) override;
  void Finish() override;

 private:
  struct Writers;
  std::string dir_;
  std::unique_ptr<Writers> writers_;
};

// Every piece to each of two sinks.
class TeeSink : public RouteSink {
 public:
  TeeSink(RouteSink& a, RouteSink& b) : a_(a), b_(b) {}
  void Start(const RouteStart& s) override { a_.Start(s), b_.Start(s); }
  void Keyframe(const route::Keyframe& k) override { a_.Keyframe(k), b_.Keyframe(k); }
  void Image(const route::StoredAppearanceImage& i) override { a_.Image(i), b_.Image(i); }
  void Finish() override { a_.Finish(), b_.Finish(); }

 private:
  RouteSink& a_;
  RouteSink& b_;
};

struct TeacherOptions {
  RouteKind kind = RouteKind::kFunnel;
  std::string detector = "orb";  // funnel
  // Eigenspace: the source never has odometry (a video or folder without poses): refuse at the
  // first frame instead of waiting for it (a robot's first frames may come before its odometry).
  bool never_odometry = false;
  int threads = 1;  // funnel: navigation::TeachOptions::threads (a robot file's `threads`)
};

// Makes the route from frames: keyframes (navigation/teach.h) or route images (the appearance
// leader, navigation/appearance.h), each handed to the sink as it is made.
class Teacher {
 public:
  Teacher(const TeacherOptions& options, RouteSink& sink);
  // Goes on from an interrupted teach (a leader restarted on its route): the route images stored
  // so far rebuild the eigenspace; a funnel teach drops its first keyframe when it has the time
  // `last_keyframe_t_ns` of the last one stored (the same keyframe again).
  // `stored`: pieces the route has already.
  void Resume(int stored, const route::StoredAppearanceRoute* images,
              std::optional<Timestamp> last_keyframe_t_ns);
  void Frame(const cv::Mat& image, Timestamp t_ns, const std::optional<Pose2>& odometry);
  // The route is complete (a funnel teach's last keyframe is kept) and the sink is finished; a
  // route of fewer than minimum() pieces is the caller's to discard.
  void Finish();
  int stored() const { return stored_; }
  int minimum() const { return 2; }
  const char* unit() const;
  int deferred_keyframes() const { return session_ ? session_->deferred_keyframes() : 0; }

 private:
  void Keep(std::optional<route::Keyframe> keyframe);
  TeacherOptions options_;
  RouteSink& sink_;
  navigation::TeachOptions teach_options_;
  std::unique_ptr<navigation::TeachSession> session_;
  navigation::AppearanceLeader leader_;
  bool started_ = false;
  int stored_ = 0;
  int without_odometry_ = 0;
  std::optional<Timestamp> drop_keyframe_at_;
};

// One frame as the teach loop hands it on (to be recorded, say) before the teacher has it.
using FrameTap =
    std::function<void(const robot::Observation& frame, const std::optional<Pose2>& truth)>;

// A tap that shows each frame of a teach in the live view (live/live_view.h: `--live`), with how
// much route the teacher has made so far, then hands the frame to `then`. `view` null: `then`.
FrameTap LiveTeachTap(live::LiveView* view, const Teacher& teacher, FrameTap then = {});

struct TeachOutcome {
  int frames = 0;
  bool interrupted = false;   // the user ended it (Ctrl-C): the normal end on a live link
  std::string end;            // why frames stopped: the end of the recording, the link closed, ...
  bool source_ended = false;  // a recording's or the scripted drive's normal end
  bool failed = false;        // the link closed (a robot gone) or the drive did not complete
};

// Frames from `link` to the teacher until the link closes or `interrupted()` (default: the
// process-wide interrupt). The teacher's route is not finished here.
TeachOutcome TeachFromLink(robot::RobotLink& link, Teacher& teacher, const FrameTap& tap = {},
                           const std::function<bool()>& interrupted = {});

// The simulator: the scenario's taught path driven and rendered; `skip` frames are driven but not
// rendered (a leader resuming its route); `pace` is called with each rendered frame's time (a
// leader in step with the wall clock).
TeachOutcome TeachOnSimulator(const sim::Scenario& scenario, Teacher& teacher,
                              const FrameTap& tap = {},
                              const std::function<bool(const sim::DriveFrame&)>& skip = {},
                              const std::function<void(Timestamp)>& pace = {},
                              const std::function<bool()>& interrupted = {});

}  // namespace mapless::run
