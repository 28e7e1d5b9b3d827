#include "mapless/eval/generated.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <exception>

#include "mapless/core/check.h"
#include "mapless/eval/eigenspace.h"
#include "mapless/eval/potential.h"
#include "mapless/eval/suite.h"
#include "mapless/eval/teach_repeat.h"

namespace mapless::eval {

namespace {

// Turns the frames' (held, reason) into stops, each judged against the objects added at repeat
// time.
class StopRecorder {
 public:
  StopRecorder(const sim::Scenario& scenario, const GeneratedRunOptions& options)
      : added_(ObjectsAddedAtRepeat(scenario)),
        period_s_(1.0 / scenario.camera.rate_hz),
        radius_m_(scenario.robot.radius_m),
        near_m_(options.obstacle_near_m) {}

  void Frame(const Pose2& truth, bool held, const std::string& reason, GeneratedWorldResult* out) {
    const double t = period_s_ * static_cast<double>(frames_++);
    out->path.push_back(truth);
    if (!held) {
      open_ = false;
      return;
    }
    const sim::World now = sim::WorldAt(added_, t);
    const bool near =
        !now.objects.empty() && sim::ClearanceTo(now, truth.x_m, truth.y_m) - radius_m_ <= near_m_;
    if (!open_) {
      out->stops.push_back({t, 0.0, reason, near});
      open_ = true;
    }
    GeneratedStop& stop = out->stops.back();
    stop.duration_s = t + period_s_ - stop.start_s;
    stop.at_obstacle = stop.at_obstacle || near;
    if (near && !out->collided) out->stopped_at_obstacle = true;
  }
  // The run ended in the stop now open (the loop's max_blocked_s, or the method gave up there).
  bool ended_in_stop() const { return open_; }

 private:
  sim::World added_;
  double period_s_;
  double radius_m_;
  double near_m_;
  int frames_ = 0;
  bool open_ = false;
};

bool StartsWith(const std::string& s, const std::string& prefix) {
  return s.compare(0, prefix.size(), prefix) == 0;
}

void RunFunnel(const sim::Scenario& scenario, const GeneratedRunOptions& options,
               GeneratedWorldResult* out) {
  const TaughtRoute taught = TeachOnSimulator(scenario, navigation::TeachOptions{});
  out->reference_path = taught.path;
  RepeatRunOptions o;
  o.seed = options.seed;
  o.max_blocked_s = options.max_blocked_s;
  o.repeat.obstacle.enabled = options.watch;
  const double speed = RepeatSpeedFor(scenario, o.max_repeat_speed_mps);
  o.repeat.sloped.max_speed_mps = speed;
  o.repeat.standard.forward_speed_mps = speed;
  StopRecorder stops(scenario, options);
  const RepeatRun run =
      RepeatOnSimulator(scenario, taught, o,
                        [&](const Pose2& truth, const cv::Mat&, const navigation::RepeatStep& s) {
                          const bool held = s.status == navigation::RepeatStatus::kBlocked ||
                                            s.status == navigation::RepeatStatus::kWaiting ||
                                            s.status == navigation::RepeatStatus::kAborted;
                          stops.Frame(truth, held, s.reason, out);
                        });
  out->arrived = run.completed;
  out->collided = run.collided;
  out->end_reason = run.status;
  out->final_error_m = run.final_error_m;
  out->duration_s = run.duration_s;
  out->success = run.success;
  if (out->obstacle && !run.collided && stops.ended_in_stop() && !out->stops.empty() &&
      out->stops.back().at_obstacle)
    out->success = true;
}

void RunFollower(const sim::Scenario& scenario, const GeneratedRunOptions& options,
                 GeneratedWorldResult* out) {
  EigenspaceRunOptions o;
  o.seed = options.seed;
  o.motion_noise = 0.1;
  o.max_blocked_s = options.max_blocked_s;
  o.follower.obstacle.enabled = options.watch;
  StopRecorder stops(scenario, options);
  const EigenspaceRun run =
      RunEigenspaceFollow(scenario, o, [&](const navigation::FollowerStep& s, const Pose2& truth) {
        const bool held = s.state == navigation::FollowerState::kStopped;
        stops.Frame(truth, held, s.reason, out);
      });
  out->reference_path = run.leader_path;
  out->arrived = run.status.empty();  // Finalize leaves it empty when the follower arrived
  out->collided = run.collided;
  out->end_reason = run.status.empty() ? "arrived" : run.status;
  out->final_error_m = run.final_error_m;
  out->duration_s = static_cast<double>(out->path.size()) / scenario.camera.rate_hz;
  out->success = run.success;
  if (out->obstacle && !run.collided && stops.ended_in_stop() && !out->stops.empty() &&
      out->stops.back().at_obstacle)
    out->success = true;
}

void RunPotentialWorld(const sim::Scenario& given, const GeneratedRunOptions& options,
                       GeneratedWorldResult* out) {
  const sim::Scenario scenario = PotentialWorld(given);
  MAPLESS_CHECK(!scenario.destinations.empty(),
                "generated world " << scenario.name << ": no destination for the potential");
  PotentialRunOptions o;
  o.seed = options.seed;
  o.nav.noise_seed = options.seed;
  o.motion_noise_frac = 0.1;
  o.image_noise_sigma = 2.0;
  o.destination = scenario.destinations.front();
  o.max_blocked_s = options.max_blocked_s;
  const navigation::PlanarFlowCalibration calibration = CalibrateOnSimulator(scenario, o.nav);
  out->reference_path = {scenario.teach_start, Pose2{o.destination->x(), o.destination->y(), 0.0}};
  StopRecorder stops(scenario, options);
  const PotentialRun run =
      RunPotential(scenario, calibration, o,
                   [&](const Pose2& truth, const cv::Mat&, const navigation::PotentialStep& s) {
                     const bool held = s.status == navigation::PotentialStatus::kSearching ||
                                       s.status == navigation::PotentialStatus::kAborted ||
                                       s.status == navigation::PotentialStatus::kCameraFault;
                     stops.Frame(truth, held, s.reason, out);
                   });
  out->arrived = run.reached;
  out->collided = run.collided;
  out->end_reason = run.status;
  out->final_error_m = run.final_error_m;
  out->duration_s = run.duration_s;
  out->success = run.success;
}

}  // namespace

void GeneratedRunOptions::Validate() const {
  MAPLESS_CHECK(
      method == "funnel" || method == "eigenspace" || method == "potential",
      "GeneratedRunOptions.method = '" << method << "'; must be funnel, eigenspace or potential");
  MAPLESS_CHECK(std::isfinite(max_blocked_s) && max_blocked_s > 0.0,
                "GeneratedRunOptions.max_blocked_s = " << max_blocked_s << "; must be > 0");
  MAPLESS_CHECK(obstacle_near_m > 0.0,
                "GeneratedRunOptions.obstacle_near_m = " << obstacle_near_m << "; must be > 0");
}

int GeneratedWorldResult::false_stops() const {
  return static_cast<int>(std::count_if(stops.begin(), stops.end(),
                                        [](const GeneratedStop& s) { return !s.at_obstacle; }));
}

double GeneratedWorldResult::longest_false_stop_s() const {
  double longest = 0.0;
  for (const GeneratedStop& s : stops)
    if (!s.at_obstacle) longest = std::max(longest, s.duration_s);
  return longest;
}

sim::Scenario PotentialWorld(sim::Scenario scenario) {
  // Ohnishi & Imiya's camera looks down at the ground in front of the robot (the potential
  // suite's scenarios: 90 degrees, 1 m high, 40 degrees down).
  scenario.camera.model = sim::CameraModel::FromFov(320, 240, DegToRad(90.0));
  scenario.camera.mount.height_m = 1.0;
  scenario.camera.mount.pitch_rad = DegToRad(40.0);
  return scenario;
}

GeneratedWorldResult RunGeneratedWorld(const sim::Scenario& scenario,
                                       const GeneratedRunOptions& options) {
  options.Validate();
  GeneratedWorldResult out;
  out.world = scenario.name;
  const auto label = [&](const std::string& key) {
    const auto it = scenario.labels.find(key);
    return it == scenario.labels.end() ? std::string() : it->second;
  };
  out.kind = label("kind");
  out.feasible = label("feasible") != "false";
  out.obstacle = !label("obstacle_on_path").empty() && label("obstacle_on_path") != "none";
  try {
    if (options.method == "funnel") {
      RunFunnel(scenario, options, &out);
    } else if (options.method == "eigenspace") {
      RunFollower(scenario, options, &out);
    } else {
      RunPotentialWorld(scenario, options, &out);
    }
  } catch (const std::exception& e) {
    // A world the scripted teach cannot drive, or a method that refuses it: an answer, with why.
    out.success = false;
    out.end_reason = e.what();
  }
  out.no_answer = StartsWith(out.end_reason, "timeout");
  return out;
}

std::string StopKind(const std::string& reason) {
  std::string out;
  bool in_number = false;
  for (char c : reason) {
    const bool digit =
        std::isdigit(static_cast<unsigned char>(c)) != 0 || (in_number && (c == '.' || c == '-'));
    if (digit) {
      if (!in_number) out += '#';
      in_number = true;
    } else {
      in_number = false;
      out += c;
    }
  }
  const std::size_t colon = out.find(": stopped");
  return colon == std::string::npos ? out : out.substr(0, colon);
}

}  // namespace mapless::eval
