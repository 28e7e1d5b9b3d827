#include "mapless/run/sim_episode.h"

#include <chrono>
#include <nlohmann/json.hpp>
#include <thread>

#include "mapless/core/check.h"
#include "mapless/eval/eigenspace.h"
#include "mapless/eval/potential.h"
#include "mapless/run/decision_log.h"

namespace mapless::run {

void Pacer::At(Timestamp sim_ns) {
  if (rate_ <= 0.0) return;
  using Clock = std::chrono::steady_clock;
  const std::int64_t now =
      std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now().time_since_epoch()).count();
  if (!started_) {
    started_ = true;
    wall0_ns_ = now;
    sim0_ = sim_ns;
    return;
  }
  const auto due = static_cast<std::int64_t>(static_cast<double>(sim_ns - sim0_) / rate_);
  if (wall0_ns_ + due > now)
    std::this_thread::sleep_for(std::chrono::nanoseconds(wall0_ns_ + due - now));
}

SimEpisode FollowEpisode(const sim::Scenario& scenario, fleet::RouteKind kind, std::uint64_t seed,
                         double motion_noise, bool live_leader) {
  SimEpisode episode;
  sim::DriveOptions path_only;
  path_only.render_frames = false;
  const sim::DriveSummary drive = sim::DriveTaughtPath(
      scenario, path_only, [&](const sim::DriveFrame& f) { episode.taught.push_back(f.truth); });
  if (episode.taught.empty()) episode.taught.push_back(scenario.teach_start);
  episode.taught_duration_s = drive.duration_s;
  const double factor = live_leader ? 2.0 : 1.0;
  if (kind == fleet::RouteKind::kFunnel) {
    eval::RepeatRunOptions run;
    run.seed = seed;
    run.motion_noise_frac = motion_noise;
    episode.setup = eval::RepeatSimSetup(scenario, run);
    episode.timeout_s = factor * run.timeout_factor * std::max(drive.duration_s, 1.0);
    episode.tolerance_m = run.success_radius_m;
  } else {
    eval::EigenspaceRunOptions run;
    run.seed = seed;
    run.motion_noise = motion_noise;
    episode.setup = eval::FollowSimSetup(scenario, run);
    episode.timeout_s = factor * eval::FollowTimeoutS(scenario, run);
    episode.tolerance_m = run.arrive_tolerance_m;
  }
  return episode;
}

eval::SimSetup SimSetupLike(const sim::Scenario& scenario, const std::string& like,
                            std::uint64_t seed, double motion_noise, double image_noise) {
  if (like == "teach") {
    eval::SimSetup setup;
    setup.world = scenario.world;
    setup.camera = scenario.camera;
    setup.robot = scenario.robot;
    setup.start = scenario.teach_start;
    setup.seed = seed;
    return setup;
  }
  if (like == "repeat") {
    eval::RepeatRunOptions o;
    o.seed = seed;
    o.motion_noise_frac = motion_noise;
    o.image_noise_sigma = image_noise;
    return eval::RepeatSimSetup(scenario, o);
  }
  if (like == "navigate") {
    eval::PotentialRunOptions o;
    o.seed = seed;
    o.motion_noise_frac = motion_noise;
    o.image_noise_sigma = image_noise;
    return eval::PotentialSimSetup(scenario, o);
  }
  if (like == "follow") {
    eval::EigenspaceRunOptions o;
    o.seed = seed;
    o.motion_noise = motion_noise;
    return eval::FollowSimSetup(scenario, o);
  }
  throw InputError("--like " + like + ": must be teach, repeat, navigate or follow");
}

// The simulator's link paced to the wall clock.
class SimRun::Paced : public robot::RobotLink {
 public:
  Paced(robot::SimLink& link, double rate) : link_(link), pacer_(rate) {}
  robot::LinkEvent Next() override {
    robot::LinkEvent e = link_.Next();
    pacer_.At(link_.now_ns());
    return e;
  }
  void Send(const Twist2& c, const robot::Observation& o, const robot::Decision& d) override {
    link_.Send(c, o, d);
  }
  void Stop(const std::string& reason) override { link_.Stop(reason); }
  std::string Halted() override { return link_.Halted(); }
  Timestamp now_ns() const override { return link_.now_ns(); }
  std::optional<Pose2> GroundTruth() const override { return link_.GroundTruth(); }

 private:
  robot::SimLink& link_;
  Pacer pacer_;
};

namespace {
robot::SimLinkOptions LinkOptions(const sim::Scenario& scenario, const SimEpisode& episode) {
  robot::SimLinkOptions o;
  o.period_s = 1.0 / scenario.camera.rate_hz;
  o.timeout_s = episode.timeout_s;
  return o;
}
}  // namespace

SimRun::SimRun(const sim::Scenario& scenario, SimEpisode episode, double rate)
    : episode_(std::move(episode)),
      sim_(episode_.setup.world, episode_.setup.camera, {}, episode_.setup.seed),
      robot_(sim_.AddRobot(episode_.setup.start, episode_.setup.robot)),
      link_(sim_, robot_, LinkOptions(scenario, episode_)) {
  if (rate > 0.0) paced_ = std::make_unique<Paced>(link_, rate);
}

SimRun::~SimRun() = default;

robot::RobotLink& SimRun::link() {
  if (paced_) return *paced_;
  return link_;
}
const Pose2& SimRun::truth() const { return link_.truth(); }
bool SimRun::collided() const { return sim_.collided(robot_); }
double SimRun::error_at_end_m() const { return truth().DistanceTo(episode_.taught.back()); }
bool SimRun::succeeded(bool method_finished) const {
  return method_finished && !collided() && error_at_end_m() <= episode_.tolerance_m;
}

void SimRun::AddTruth(nlohmann::json* j) const { run::AddTruth(truth(), j); }

}  // namespace mapless::run
