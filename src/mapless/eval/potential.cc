#include "mapless/eval/potential.h"

#include <algorithm>
#include <cmath>

#include "mapless/control/funnel_lane.h"
#include "mapless/core/check.h"
#include "mapless/core/rng.h"
#include "mapless/eval/teach_repeat.h"
#include "mapless/flow/flow.h"
#include "mapless/robot/loop.h"
#include "mapless/robot/methods.h"
#include "mapless/robot/sim_link.h"
#include "mapless/sim/renderer.h"
#include "mapless/sim/simulation.h"

namespace mapless::eval {
namespace {

// The scenario's taught path as points (start first).
std::vector<Eigen::Vector2d> PathPoints(const sim::Scenario& s) {
  std::vector<Eigen::Vector2d> pts{{s.teach_start.x_m, s.teach_start.y_m}};
  for (const auto& step : s.teach_path)
    if (step.kind == sim::PathStep::Kind::kGoTo) pts.push_back(step.target);
  return pts;
}

double Rms(const std::vector<double>& v) {
  double s = 0.0;
  for (double x : v) s += x * x;
  return v.empty() ? 0.0 : std::sqrt(s / static_cast<double>(v.size()));
}

}  // namespace

navigation::PlanarFlowCalibration CalibrateOnSimulator(const sim::Scenario& scenario,
                                                       const navigation::PotentialNavOptions& nav,
                                                       int frames) {
  MAPLESS_CHECK(frames >= 2, "calibration frames = " << frames << "; must be >= 2");
  navigation::PlanarFlowCalibration c;
  c.width = scenario.camera.model.width;
  c.height = scenario.camera.model.height;
  c.period_s = 1.0 / scenario.camera.rate_hz;
  c.speed_mps = nav.potential.max_translation_mps;
  c.omega_radps = nav.potential.max_rotation_radps;
  sim::CameraSpec camera = scenario.camera;
  camera.effects = {};
  sim::RobotOptions robot = scenario.robot;
  robot.motion_noise_v_frac = robot.motion_noise_omega_frac = 0.0;
  auto drive = [&](const Twist2& twist) {
    sim::Simulation sim(scenario.world, camera, {}, scenario.seed);
    const int r = sim.AddRobot(scenario.teach_start, robot);
    // Reach the constant velocity first (the robot accelerates within its limits).
    sim.SetCommand(r, twist);
    sim.Advance(1.0);
    std::vector<cv::Mat> images;
    for (int i = 0; i < frames; ++i) {
      images.push_back(sim.Render(r));
      sim.Advance(c.period_s);
    }
    return navigation::CalibratePlanarModel(images, nav.flow, nav.plane);
  };
  c.translational = drive({c.speed_mps, 0.0});
  c.rotational = drive({0.0, c.omega_radps});
  return c;
}

void PotentialRunOptions::Validate() const {
  nav.Validate();
  MAPLESS_CHECK(motion_noise_frac >= 0.0 && motion_noise_frac < 1.0,
                "motion_noise_frac = " << motion_noise_frac << "; must be in [0, 1)");
  MAPLESS_CHECK(invert_fraction >= 0.0 && invert_fraction <= 1.0,
                "invert_fraction = " << invert_fraction << "; must be in [0, 1]");
  MAPLESS_CHECK(timeout_factor > 0.0 && success_radius_m > 0.0,
                "timeout_factor and success_radius_m must be > 0");
}

SimSetup PotentialSimSetup(const sim::Scenario& scenario, const PotentialRunOptions& options) {
  options.Validate();
  Rng rng(options.seed);
  SimSetup setup;
  setup.camera = scenario.camera;
  if (scenario.repeat_effects) setup.camera.effects = *scenario.repeat_effects;
  setup.camera.effects.invert_fraction =
      std::max(setup.camera.effects.invert_fraction, options.invert_fraction);
  setup.camera.effects.noise_sigma =
      std::max(setup.camera.effects.noise_sigma, options.image_noise_sigma);
  setup.robot = scenario.robot;
  setup.robot.motion_noise_v_frac = options.motion_noise_frac;
  setup.robot.motion_noise_omega_frac = options.motion_noise_frac;
  setup.start = scenario.teach_start * Pose2{0.0, options.start_lateral_m, 0.0};
  // What has changed since the world was described (objects put down), as for a repeat.
  setup.world = sim::ApplyVariant(scenario.world, scenario.repeat_variant);
  setup.seed = rng.NextU64();
  return setup;
}

PotentialRun RunPotential(const sim::Scenario& scenario,
                          const navigation::PlanarFlowCalibration& calibration,
                          const PotentialRunOptions& options, const PotentialObserver& observer) {
  const SimSetup setup = PotentialSimSetup(scenario, options);
  const Pose2& start = setup.start;
  sim::Simulation sim(setup.world, setup.camera, {}, setup.seed);
  const int r = sim.AddRobot(setup.start, setup.robot);

  navigation::PotentialNavOptions nav = options.nav;
  nav.homing = options.homing;
  const std::vector<Eigen::Vector2d> taught = PathPoints(scenario);
  double length = 0.0;
  for (std::size_t i = 1; i < taught.size(); ++i) length += (taught[i] - taught[i - 1]).norm();
  Eigen::Vector2d goal(start.x_m, start.y_m);
  if (options.destination) {
    length = (*options.destination - goal).norm() * (options.homing ? 2.0 : 1.0);
    if (!options.homing) goal = *options.destination;
  }
  MAPLESS_CHECK(taught.size() >= 2 || options.destination,
                "scenario '" << scenario.name << "' has no taught path for corridor centring");
  robot::PotentialMethod method(calibration, nav, options.destination);
  const Eigen::Vector2d end = taught.back();
  const Eigen::Vector2d end_dir = (taught.back() - taught[taught.size() - 2]).normalized();
  robot::SimLinkOptions link_options;
  link_options.period_s = 1.0 / scenario.camera.rate_hz;
  link_options.timeout_s =
      options.timeout_factor * length / nav.potential.max_translation_mps + 20.0;
  link_options.camera_faults = options.camera_faults;
  link_options.fault_seed = options.seed;
  robot::SimLink link(sim, r, link_options);
  const std::unique_ptr<robot::RobotLink> wrapped =
      options.wrap_link ? options.wrap_link(link) : nullptr;

  PotentialRun run;
  bool passed_end = false;
  const robot::LoopResult result = robot::RunLoop(
      method, wrapped ? *wrapped : static_cast<robot::RobotLink&>(link),
      BlockedLoop(options.max_blocked_s),
      [&](const robot::Observation& obs, const robot::Decision& decision) {
        const auto& step = decision.DetailAs<robot::PotentialDetail>()->step;
        const Pose2 pose = link.truth();
        run.path.push_back(pose);
        if (observer) observer(pose, obs.image, step);
        if (step.status == navigation::PotentialStatus::kSearching && !step.plane_mask.empty())
          ++run.no_plane_frames;
        if (!options.destination &&
            (Eigen::Vector2d(pose.x_m, pose.y_m) - end).dot(end_dir) >= 0.0) {
          passed_end = true;
          return false;
        }
        return true;
      });
  if (passed_end) {
    run.reached = true;
    run.status = "passed the end of the corridor";
  } else {
    run.reached = result.finished;
    run.status = result.reason;
    run.collided = sim.collided(r);
  }
  run.duration_s = ToSeconds(sim.now_ns());
  const Pose2& last = run.path.back();
  run.final_error_m =
      options.destination ? (Eigen::Vector2d(last.x_m, last.y_m) - goal).norm() : 0.0;
  run.success = run.reached && !run.collided && run.final_error_m <= options.success_radius_m;
  return run;
}

double SignedDistanceToPath(const std::vector<Pose2>& path, double x_m, double y_m) {
  MAPLESS_CHECK(!path.empty(), "SignedDistanceToPath: empty path");
  if (path.size() == 1) return std::hypot(x_m - path[0].x_m, y_m - path[0].y_m);
  double best = std::numeric_limits<double>::infinity();
  double best_signed = 0.0;
  const Eigen::Vector2d p(x_m, y_m);
  for (std::size_t i = 1; i < path.size(); ++i) {
    const Eigen::Vector2d a(path[i - 1].x_m, path[i - 1].y_m);
    const Eigen::Vector2d b(path[i].x_m, path[i].y_m);
    const Eigen::Vector2d ab = b - a;
    const double len2 = ab.squaredNorm();
    if (len2 < 1e-12) continue;
    const double t = std::clamp((p - a).dot(ab) / len2, 0.0, 1.0);
    const Eigen::Vector2d q = a + t * ab;
    const double d = (p - q).norm();
    if (d < best) {
      best = d;
      const double cross = ab.x() * (p - a).y() - ab.y() * (p - a).x();
      best_signed = cross >= 0.0 ? d : -d;
    }
  }
  return std::isfinite(best) ? best_signed : std::hypot(x_m - path[0].x_m, y_m - path[0].y_m);
}

double TrajectoryDeviationStd(const std::vector<Pose2>& clean, const std::vector<Pose2>& noisy) {
  const std::size_t n = std::min(clean.size(), noisy.size());
  std::vector<double> diff;
  diff.reserve(n);
  for (std::size_t i = 0; i < n; ++i)
    diff.push_back(SignedDistanceToPath(clean, noisy[i].x_m, noisy[i].y_m));
  return control::StdDev(diff);
}

InclusionResult InclusionOnSimulator(const sim::Scenario& scenario,
                                     const ground::DominantPlaneOptions& plane, int max_pairs,
                                     double speed_mps) {
  MAPLESS_CHECK(speed_mps > 0.0, "inclusion drive speed = " << speed_mps << "; must be > 0");
  sim::Scenario slow = scenario;
  slow.teach_speed_mps = speed_mps;
  for (auto& step : slow.teach_path) step.speed_mps = 0.0;
  InclusionResult result;
  result.scenario = scenario.name;
  result.inclusion.assign(3, 0.0);
  flow::DenseLkOptions lk;
  lk.levels = 4;  // layers 0-3, as in Table 1
  cv::Mat previous;
  int frames = 0;
  sim::DriveOptions drive;
  drive.render_frames = false;  // rendered here, only for the pairs used
  const sim::Renderer renderer(scenario.world, sim::RenderOptions{});
  // One pair (frames k, k + 1) every kStride frames, spread along the path.
  constexpr int kStride = 10;
  sim::DriveTaughtPath(slow, drive, [&](const sim::DriveFrame& f) {
    if (result.pairs >= max_pairs || f.index % kStride > 1) return;
    const cv::Mat image = renderer.Render(scenario.camera.model,
                                          sim::WorldFromCamera(f.truth, scenario.camera.mount));
    if (f.index % kStride == 0) {
      previous = image;
      return;
    }
    ++result.pairs;
    std::vector<cv::Mat> layer_flows;
    flow::DenseLucasKanade(previous, image, lk, &layer_flows);
    const ground::HierarchicalPlanes h = ground::DetectHierarchicalPlanes(layer_flows, plane);
    bool all = true;
    for (const auto& l : h.layers) all = all && l.found;
    if (all && h.inclusion.size() >= 3) {
      for (std::size_t l = 0; l < 3; ++l) result.inclusion[l] += h.inclusion[l];
      ++frames;
    }
  });
  result.frames = frames;
  for (double& v : result.inclusion) v = frames > 0 ? v / frames : 0.0;
  return result;
}

std::vector<PotentialEntry> PotentialSuiteEntries() {
  return {{"corridor_straight_3p5m", "image-noise"}, {"corridor_straight_3p5m", "motion-noise"},
          {"corridor_s_shaped", "image-noise"},      {"corridor_s_shaped", "motion-noise"},
          {"obstacle_field", "destination-0"},       {"obstacle_field", "destination-1"},
          {"obstacle_field", "destination-2"},       {"obstacle_field", "homing"}};
}

PotentialEntryResult RunPotentialEntry(const PotentialEntry& entry, int runs, std::uint64_t seed,
                                       const navigation::PotentialNavOptions& nav,
                                       const PotentialObserver& first_run) {
  MAPLESS_CHECK(runs >= 1, "runs = " << runs << "; must be >= 1");
  const sim::Scenario scenario = sim::LoadScenario(entry.scenario);
  const navigation::PlanarFlowCalibration calibration = CalibrateOnSimulator(scenario, nav);
  PotentialEntryResult r;
  r.scenario = entry.scenario;
  r.controller = "potential";
  r.experiment = entry.experiment;
  r.runs = runs;
  PotentialRunOptions base;
  base.nav = nav;
  const bool corridor = entry.experiment == "image-noise" || entry.experiment == "motion-noise";
  std::vector<Pose2> clean;
  if (corridor) {
    // The straight corridor starts off-centre so that centring is exercised; the S-shaped one on
    // its centre line.
    base.start_lateral_m = entry.scenario == "corridor_straight_3p5m" ? 0.4 : 0.0;
    const PotentialRun ref = RunPotential(scenario, calibration, base);
    MAPLESS_CHECK(ref.success,
                  "the clean corridor run of " << entry.scenario << " failed: " << ref.status);
    clean = ref.path;
    r.reference_path = ref.path;
    // The paper's perturbations (Section 5.2): 20% of the dominant-plane map's pixels inverted
    // (on top of sensor noise), or 20% errors on T and R.
    if (entry.experiment == "image-noise") {
      base.nav.plane_noise_fraction = 0.2;
      base.image_noise_sigma = 2.0;
    }
    if (entry.experiment == "motion-noise") base.motion_noise_frac = 0.2;
  } else {
    // Navigation and homing: 10% motion noise and sensor noise, as in the other suites.
    base.motion_noise_frac = 0.1;
    base.image_noise_sigma = 2.0;
    const std::size_t d = entry.experiment == "homing"
                              ? 0
                              : static_cast<std::size_t>(std::stoi(entry.experiment.substr(12)));
    MAPLESS_CHECK(d < scenario.destinations.size(),
                  entry.experiment << ": scenario " << entry.scenario << " has "
                                   << scenario.destinations.size() << " destinations");
    base.destination = scenario.destinations[d];
    base.homing = entry.experiment == "homing";
  }
  std::vector<double> finals, deviations, lateral;
  for (int i = 0; i < runs; ++i) {
    PotentialRunOptions o = base;
    o.seed = seed + static_cast<std::uint64_t>(i);
    o.nav.noise_seed = o.seed;
    const PotentialRun run =
        RunPotential(scenario, calibration, o, i == 0 ? first_run : PotentialObserver{});
    r.paths.push_back(run.path);
    finals.push_back(run.final_error_m);
    if (corridor) {
      deviations.push_back(TrajectoryDeviationStd(clean, run.path));
      for (const Pose2& p : run.path) lateral.push_back(SignedDistanceToPath(clean, p.x_m, p.y_m));
    }
    if (run.success) {
      ++r.successes;
    } else {
      r.failures.push_back("run " + std::to_string(i) + " (seed " + std::to_string(o.seed) +
                           "): " + run.status + ", " +
                           std::to_string(run.final_error_m).substr(0, 4) + " m from the goal");
    }
    if (run.collided) ++r.collisions;
  }
  r.final_error_m_rms = Rms(finals);
  r.final_error_m_std = control::StdDev(finals);
  r.lateral_rms_m = Rms(lateral);
  r.deviations_m = deviations;
  if (!deviations.empty()) {
    double sum = 0.0;
    for (double d : deviations) sum += d;
    r.deviation_std_m = sum / static_cast<double>(deviations.size());
    r.deviation_std_m_max = *std::max_element(deviations.begin(), deviations.end());
  }
  return r;
}

}  // namespace mapless::eval
