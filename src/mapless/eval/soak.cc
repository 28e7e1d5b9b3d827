#include "mapless/eval/soak.h"

#include <algorithm>

#include "mapless/core/check.h"
#include "mapless/core/rng.h"
#include "mapless/navigation/repeat.h"
#include "mapless/sim/scenario.h"
#include "mapless/sim/simulation.h"

namespace mapless::eval {
namespace {

double Quantile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  const auto k = static_cast<std::size_t>(q * static_cast<double>(v.size() - 1));
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
  return v[k];
}

}  // namespace

void SoakOptions::Validate() const {
  MAPLESS_CHECK(duration_s > 0.0, "soak duration " << duration_s << " s must be positive");
  repeat.Validate();
}

SoakSummary RunSoak(const SoakOptions& options, const std::function<void(const SoakLap&)>& on_lap,
                    const std::function<double()>& now_ms) {
  options.Validate();
  const sim::Scenario scenario = sim::LoadScenario(options.scenario);
  const TaughtRoute taught = TeachOnSimulator(scenario, navigation::TeachOptions{});
  const auto route = std::const_pointer_cast<const route::Route>(taught.route);

  RepeatRunOptions o = options.repeat;
  const double speed = RepeatSpeedFor(scenario, o.max_repeat_speed_mps);
  o.repeat.sloped.max_speed_mps = speed;
  o.repeat.standard.forward_speed_mps = speed;
  sim::CameraSpec camera = scenario.camera;
  camera.effects.noise_sigma = std::max(camera.effects.noise_sigma, o.image_noise_sigma);
  sim::RobotOptions robot = scenario.robot;
  robot.motion_noise_v_frac = o.motion_noise_frac;
  robot.motion_noise_omega_frac = o.motion_noise_frac;
  Rng rng(o.seed);
  sim::Simulation sim(sim::ApplyVariant(scenario.world, scenario.repeat_variant), camera, {},
                      rng.NextU64());
  const int r = sim.AddRobot(scenario.repeat_start, robot);
  const double period = 1.0 / scenario.camera.rate_hz;
  const double lap_timeout_s = o.timeout_factor * std::max(taught.duration_s, 1.0);

  SoakSummary summary;
  std::vector<double> frame_ms;
  while (ToSeconds(sim.now_ns()) < options.duration_s) {
    const Pose2 start = scenario.repeat_start *
                        Pose2{rng.Uniform(-o.start_offset_m, o.start_offset_m),
                              rng.Uniform(-o.start_offset_m, o.start_offset_m),
                              DegToRad(rng.Uniform(-o.start_offset_deg, o.start_offset_deg))};
    sim.PlaceRobot(r, start);
    navigation::RepeatSession session(route, o.repeat);
    const double lap_start_s = ToSeconds(sim.now_ns());
    SoakLap lap;
    lap.lap = summary.laps + 1;
    frame_ms.clear();
    while (true) {
      const double t0 = now_ms ? now_ms() : 0.0;
      const cv::Mat image = sim.Render(r);
      const navigation::RepeatStep step = session.Update(image, sim.now_ns());
      frame_ms.push_back(now_ms ? now_ms() - t0 : 0.0);
      ++lap.frames;
      if (session.finished()) {
        lap.completed = step.status == navigation::RepeatStatus::kCompleted;
        break;
      }
      if (sim.collided(r)) {
        lap.collided = true;
        break;
      }
      if (ToSeconds(sim.now_ns()) - lap_start_s > lap_timeout_s) break;
      sim.SetCommand(r, step.command);
      sim.Advance(period);
    }
    sim.SetCommand(r, Twist2{});
    sim.Advance(period);  // time moves on even when a lap ends at once
    lap.end_time_s = ToSeconds(sim.now_ns());
    lap.final_error_m = sim.robot(r).pose().DistanceTo(taught.path.back());
    lap.median_frame_ms = Quantile(frame_ms, 0.5);
    lap.p95_frame_ms = Quantile(frame_ms, 0.95);
    ++summary.laps;
    summary.completed_laps += lap.completed ? 1 : 0;
    summary.frames += lap.frames;
    summary.simulated_s = lap.end_time_s;
    if (on_lap) on_lap(lap);
  }
  return summary;
}

}  // namespace mapless::eval
