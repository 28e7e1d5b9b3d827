#include "mapless/eval/teach_repeat.h"

#include <cmath>
#include <limits>

#include "mapless/core/check.h"
#include "mapless/core/rng.h"
#include "mapless/robot/loop.h"
#include "mapless/robot/methods.h"
#include "mapless/robot/sim_link.h"

namespace mapless::eval {

void RepeatRunOptions::Validate() const {
  repeat.Validate();
  MAPLESS_CHECK(
      motion_noise_frac >= 0.0 && motion_noise_frac <= 1.0,
      "RepeatRunOptions.motion_noise_frac = " << motion_noise_frac << "; must be in [0, 1]");
  MAPLESS_CHECK(image_noise_sigma >= 0.0,
                "RepeatRunOptions.image_noise_sigma = " << image_noise_sigma << "; must be >= 0");
  MAPLESS_CHECK(timeout_factor >= 1.0,
                "RepeatRunOptions.timeout_factor = " << timeout_factor << "; must be >= 1");
  MAPLESS_CHECK(success_radius_m > 0.0,
                "RepeatRunOptions.success_radius_m = " << success_radius_m << "; must be > 0");
}

double RepeatSpeedFor(const sim::Scenario& scenario, double cap_mps) {
  return std::min(scenario.teach_speed_mps, std::max(cap_mps, 0.5 * scenario.teach_speed_mps));
}

robot::LoopOptions BlockedLoop(double max_blocked_s) {
  robot::LoopOptions loop;
  loop.max_blocked_s = max_blocked_s;
  return loop;
}

double DistanceToPath(const std::vector<Pose2>& path, double x_m, double y_m) {
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i + 1 < path.size(); ++i) {
    const double ax = path[i].x_m, ay = path[i].y_m;
    const double bx = path[i + 1].x_m, by = path[i + 1].y_m;
    const double dx = bx - ax, dy = by - ay;
    const double len2 = dx * dx + dy * dy;
    double t = len2 > 0.0 ? ((x_m - ax) * dx + (y_m - ay) * dy) / len2 : 0.0;
    t = std::clamp(t, 0.0, 1.0);
    best = std::min(best, std::hypot(ax + t * dx - x_m, ay + t * dy - y_m));
  }
  if (path.size() == 1) best = std::hypot(path[0].x_m - x_m, path[0].y_m - y_m);
  return best;
}

TaughtRoute TeachOnSimulator(const sim::Scenario& scenario, const navigation::TeachOptions& options,
                             const std::function<void(const route::Keyframe&)>& on_keyframe) {
  TaughtRoute taught;
  taught.route = std::make_shared<route::Route>();
  taught.route->detector = features::DetectorTypeName(options.features.type);
  taught.route->image_width = scenario.camera.model.width;
  taught.route->image_height = scenario.camera.model.height;
  navigation::TeachSession teach(options);
  auto keep = [&](const std::optional<route::Keyframe>& kf) {
    if (!kf) return;
    if (on_keyframe) on_keyframe(*kf);
    taught.route->keyframes.push_back(*kf);
  };
  sim::DriveOptions drive;
  const sim::DriveSummary summary =
      sim::DriveTaughtPath(scenario, drive, [&](const sim::DriveFrame& f) {
        taught.path.push_back(f.truth);
        keep(teach.Update(f.image, f.t_ns, f.odometry));
      });
  keep(teach.Finish());
  MAPLESS_CHECK(summary.completed,
                "teach drive of '" << scenario.name << "' did not complete: " << summary.status);
  taught.route->complete = true;
  taught.duration_s = summary.duration_s;
  return taught;
}

SimSetup RepeatSimSetup(const sim::Scenario& scenario, const RepeatRunOptions& options) {
  options.Validate();
  Rng rng(options.seed);
  SimSetup setup;
  setup.camera = scenario.camera;
  if (scenario.repeat_effects) setup.camera.effects = *scenario.repeat_effects;
  setup.camera.effects.noise_sigma =
      std::max(setup.camera.effects.noise_sigma, options.image_noise_sigma);
  setup.robot = scenario.robot;
  setup.robot.motion_noise_v_frac = options.motion_noise_frac;
  setup.robot.motion_noise_omega_frac = options.motion_noise_frac;
  setup.start = scenario.repeat_start *
                Pose2{rng.Uniform(-options.start_offset_m, options.start_offset_m),
                      rng.Uniform(-options.start_offset_m, options.start_offset_m),
                      DegToRad(rng.Uniform(-options.start_offset_deg, options.start_offset_deg))};
  setup.world = sim::ApplyVariant(scenario.world, scenario.repeat_variant);
  setup.seed = rng.NextU64();
  return setup;
}

RepeatRun RepeatOnSimulator(const sim::Scenario& scenario, const TaughtRoute& taught,
                            const RepeatRunOptions& options, const RepeatObserver& observer) {
  options.Validate();
  const SimSetup setup = RepeatSimSetup(scenario, options);
  sim::Simulation sim(setup.world, setup.camera, {}, setup.seed);
  const int r = sim.AddRobot(setup.start, setup.robot);
  robot::RepeatMethod method(taught.route, options.repeat);
  robot::SimLinkOptions link_options;
  link_options.period_s = 1.0 / scenario.camera.rate_hz;
  link_options.timeout_s = options.timeout_factor * std::max(taught.duration_s, 1.0);
  link_options.camera_faults = options.camera_faults;
  link_options.fault_seed = options.seed;
  robot::SimLink link(sim, r, link_options);
  const std::unique_ptr<robot::RobotLink> wrapped =
      options.wrap_link ? options.wrap_link(link) : nullptr;
  RepeatRun run;
  const robot::LoopResult result =
      robot::RunLoop(method, wrapped ? *wrapped : static_cast<robot::RobotLink&>(link),
                     BlockedLoop(options.max_blocked_s),
                     [&](const robot::Observation& obs, const robot::Decision& decision) {
                       const auto& step = decision.DetailAs<robot::RepeatDetail>()->step;
                       run.path.push_back(link.truth());
                       if (observer) observer(link.truth(), obs.image, step);
                       run.steps.push_back(step);
                       return true;
                     });
  if (navigation::RepeatSession* session = method.session()) {
    run.learned = session->TakeLearned();
    run.used_views = session->used_views();
  }
  run.completed = result.finished;
  run.collided = sim.collided(r);
  run.status = result.reason;
  run.duration_s = ToSeconds(sim.now_ns());
  const Pose2& end = run.path.back();
  run.final_error_m = end.DistanceTo(taught.path.back());
  double sum = 0.0;
  for (const Pose2& p : run.path) {
    const double d = DistanceToPath(taught.path, p.x_m, p.y_m);
    sum += d * d;
  }
  run.lateral_rms_m = std::sqrt(sum / static_cast<double>(run.path.size()));
  run.success = run.completed && !run.collided && run.final_error_m <= options.success_radius_m;
  return run;
}

}  // namespace mapless::eval
