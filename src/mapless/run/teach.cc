#include "mapless/run/teach.h"

#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>

#include "mapless/core/check.h"
#include "mapless/core/interrupt.h"
#include "mapless/features/features.h"
#include "mapless/recording/playback.h"
#include "mapless/robot/status.h"
#include "mapless/route/route_store.h"

namespace mapless::run {

RouteKind ParseTeachMethod(const std::string& text) {
  if (text == "funnel") return RouteKind::kFunnel;
  if (text == "eigenspace") return RouteKind::kEigenspace;
  throw InputError("--method " + text + ": must be funnel or eigenspace");
}

// ---- the route store ---------------------------------------------------------------------------

struct StoreSink::Writers {
  std::unique_ptr<route::RouteWriter> keyframes;
  std::unique_ptr<route::AppearanceRouteWriter> images;
};

StoreSink::StoreSink(std::string dir) : dir_(std::move(dir)), writers_(new Writers) {}
StoreSink::~StoreSink() = default;

void StoreSink::Start(const RouteStart& s) {
  if (s.kind == RouteKind::kFunnel) {
    writers_->keyframes =
        std::make_unique<route::RouteWriter>(dir_, s.detector, s.image_width, s.image_height);
  } else {
    writers_->images = std::make_unique<route::AppearanceRouteWriter>(
        dir_, s.image_width, s.image_height, s.low_width, s.low_height);
  }
}

void StoreSink::Keyframe(const route::Keyframe& keyframe) { writers_->keyframes->Append(keyframe); }
void StoreSink::Image(const route::StoredAppearanceImage& image) {
  writers_->images->Append(image);
}

void StoreSink::Finish() {
  if (writers_->keyframes) writers_->keyframes->Finish();
  if (writers_->images) writers_->images->Finish();
}

// ---- the teacher -------------------------------------------------------------------------------

Teacher::Teacher(const TeacherOptions& options, RouteSink& sink) : options_(options), sink_(sink) {
  if (options_.kind == RouteKind::kFunnel) {
    teach_options_.features.type = features::ParseDetectorType(options_.detector);
    teach_options_.threads = options_.threads;
    teach_options_.Validate();
    session_ = std::make_unique<navigation::TeachSession>(teach_options_);
  }
}

const char* Teacher::unit() const {
  return options_.kind == RouteKind::kFunnel ? "keyframes" : "route images";
}

void Teacher::Resume(int stored, const route::StoredAppearanceRoute* images,
                     std::optional<Timestamp> last_keyframe_t_ns) {
  started_ = true;
  stored_ = stored;
  if (images) {
    for (const auto& image : images->images)
      leader_.AddStored(image.low, image.distance_m, image.odometry);
  }
  drop_keyframe_at_ = last_keyframe_t_ns;
}

void Teacher::Frame(const cv::Mat& image, Timestamp t_ns, const std::optional<Pose2>& odometry) {
  const bool funnel = options_.kind == RouteKind::kFunnel;
  if (!funnel && !odometry) {
    // A robot's first frames may come before its first odometry message: skip them, but not for
    // ever.
    if (++without_odometry_ < 30 && !options_.never_odometry) return;
    throw InputError(
        "--method eigenspace needs wheel odometry (route images are spaced by distance): teach "
        "on sim:SCENARIO, on a robot or a recording with an odometry topic, or on a video or "
        "image folder with --poses FILE.tum");
  }
  if (!started_) {
    RouteStart start;
    start.kind = options_.kind;
    start.image_width = image.cols;
    start.image_height = image.rows;
    start.detector = options_.detector;
    const navigation::AppearanceLeaderOptions appearance;
    start.low_width = appearance.image.width;
    start.low_height = appearance.image.height;
    sink_.Start(start);
    started_ = true;
  }
  if (funnel) {
    Keep(session_->Update(image, t_ns, odometry));
    return;
  }
  if (leader_.Update(image, *odometry)) {
    sink_.Image({leader_.last_low(), leader_.distance_m(), *odometry, {}});
    ++stored_;
  }
}

void Teacher::Keep(std::optional<route::Keyframe> keyframe) {
  if (!keyframe) return;
  if (drop_keyframe_at_ && keyframe->t_ns == *drop_keyframe_at_) {
    drop_keyframe_at_.reset();  // a resumed session's first keyframe is the stored last one
    return;
  }
  drop_keyframe_at_.reset();
  sink_.Keyframe(*keyframe);
  ++stored_;
}

void Teacher::Finish() {
  if (!started_) return;
  if (session_) Keep(session_->Finish());
  sink_.Finish();
}

// ---- the teach loop ----------------------------------------------------------------------------

namespace {

// What the live view shows of a teach frame: the route made so far.
class TeachDetail : public robot::DecisionDetail {
 public:
  TeachDetail(int stored, const char* unit) : stored_(stored), unit_(unit) {}
  void Fields(nlohmann::json* j) const override { (*j)["stored"] = stored_; }
  void Draw(cv::Mat*, double, std::vector<std::string>* lines) const override {
    lines->push_back(std::to_string(stored_) + " " + unit_ + " so far");
  }

 private:
  int stored_;
  const char* unit_;
};

}  // namespace

FrameTap LiveTeachTap(live::LiveView* view, const Teacher& teacher, FrameTap then) {
  if (view == nullptr) return then;
  return [view, &teacher, then](const robot::Observation& f, const std::optional<Pose2>& truth) {
    robot::Decision d;
    d.state = robot::MethodState::kDriving;  // a person drives; the teach records
    d.status = "teaching";
    d.detail = std::make_shared<TeachDetail>(teacher.stored(), teacher.unit());
    view->Frame(f, d, Twist2{}, truth);
    if (then) then(f, truth);
  };
}

TeachOutcome TeachFromLink(robot::RobotLink& link, Teacher& teacher, const FrameTap& tap,
                           const std::function<bool()>& interrupted) {
  const std::function<bool()> stop =
      interrupted ? interrupted : [] { return InterruptRequested(); };
  TeachOutcome outcome;
  while (true) {
    if (stop()) break;
    robot::LinkEvent e = link.Next();
    if (stop()) break;  // the link heard the interrupt first
    if (e.type == robot::LinkEventType::kClosed) {
      outcome.end = e.reason;
      outcome.source_ended = e.reason == recording::kEndOfRecording;
      outcome.failed = !outcome.source_ended;
      return outcome;
    }
    if (e.type != robot::LinkEventType::kFrame) continue;
    if (tap) tap(e.observation, std::nullopt);
    teacher.Frame(e.observation.image, e.observation.t_ns, e.observation.odometry);
    ++outcome.frames;
  }
  outcome.interrupted = true;
  outcome.end = "interrupted";
  return outcome;
}

TeachOutcome TeachOnSimulator(const sim::Scenario& scenario, Teacher& teacher, const FrameTap& tap,
                              const std::function<bool(const sim::DriveFrame&)>& skip,
                              const std::function<void(Timestamp)>& pace,
                              const std::function<bool()>& interrupted) {
  const std::function<bool()> stop =
      interrupted ? interrupted : [] { return InterruptRequested(); };
  struct Stopped {};
  TeachOutcome outcome;
  sim::DriveOptions drive;
  drive.skip_render = skip;
  sim::DriveSummary summary;
  try {
    summary = sim::DriveTaughtPath(scenario, drive, [&](const sim::DriveFrame& f) {
      if (stop()) throw Stopped{};
      if (f.image.empty()) return;  // driven, not rendered (skip)
      if (pace) pace(f.t_ns);
      robot::Observation frame{f.image, f.t_ns, f.odometry};
      if (tap) tap(frame, f.truth);
      teacher.Frame(f.image, f.t_ns, f.odometry);
      ++outcome.frames;
    });
  } catch (const Stopped&) {
    outcome.interrupted = true;
    outcome.end = "interrupted";
    return outcome;
  }
  if (!summary.completed) {
    outcome.failed = true;
    outcome.end = "the drive of '" + scenario.name + "' did not complete: " + summary.status;
    return outcome;
  }
  outcome.source_ended = true;
  outcome.end = "the taught path's end";
  return outcome;
}

}  // namespace mapless::run
