#include "mapless/eval/eigenspace.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>

#include "mapless/appearance/image.h"
#include "mapless/core/check.h"
#include "mapless/eval/potential.h"
#include "mapless/eval/teach_repeat.h"
#include "mapless/localization/nearest.h"
#include "mapless/navigation/appearance_experiences.h"
#include "mapless/robot/loop.h"
#include "mapless/robot/methods.h"
#include "mapless/robot/sim_link.h"
#include "mapless/sim/driver.h"
#include "mapless/sim/simulation.h"

namespace mapless::eval {
namespace {

// The route image taken nearest to (x, y) among the first `count`: the true position on the route.
int NearestRouteImage(const std::vector<Pose2>& image_truth, int count, double x_m, double y_m) {
  int best = -1;
  double best_d = std::numeric_limits<double>::infinity();
  for (int i = 0; i < count; ++i) {
    const double d = std::hypot(image_truth[static_cast<std::size_t>(i)].x_m - x_m,
                                image_truth[static_cast<std::size_t>(i)].y_m - y_m);
    if (d < best_d) {
      best_d = d;
      best = i;
    }
  }
  return best;
}

// Accumulates the follower's metrics frame by frame.
struct FollowerMetrics {
  double travelled_m = 0.0;
  bool have_last = false;
  Pose2 last;
  int frames = 0;
  int within_one = 0;
  int nearest_within_one = 0;
  double lateral_sq = 0.0;
  int stops = 0;
  int obstacle_stops = 0;  // times the obstacle watch stopped the follower
  bool was_blocked = false;
  bool converged = false;
  double converged_at_m = -1.0;

  void Add(const Pose2& truth, const navigation::FollowerStep& step, const cv::Mat& image,
           const route::AppearanceRoute& route, const std::vector<Pose2>& image_truth,
           const std::vector<Pose2>& leader_path, const EigenspaceRunOptions& options) {
    if (have_last) travelled_m += truth.DistanceTo(last);
    have_last = true;
    last = truth;
    if (step.state == navigation::FollowerState::kStopped) ++stops;
    if (step.obstacle.blocked && !was_blocked) ++obstacle_stops;
    was_blocked = step.obstacle.blocked;
    const double lateral = SignedDistanceToPath(leader_path, truth.x_m, truth.y_m);
    if (!converged && travelled_m >= options.convergence_m &&
        std::abs(lateral) <= options.converged_lateral_m) {
      converged = true;
      converged_at_m = travelled_m;
    }
    if (!converged || step.state != navigation::FollowerState::kFollowing) return;
    ++frames;
    const int truth_index = NearestRouteImage(image_truth, route.size(), truth.x_m, truth.y_m);
    within_one += std::abs(step.index - truth_index) <= 1;
    const appearance::Vector z =
        route.space.Project(appearance::AppearanceVector(image, options.follower.image));
    const int nn = localization::NearestProjection(route.space.projections, z).index;
    nearest_within_one += std::abs(nn - truth_index) <= 1;
    lateral_sq += lateral * lateral;
  }
};

Pose2 StartPose(const sim::Scenario& scenario, const EigenspaceRunOptions& options) {
  return scenario.teach_start * options.start_offset;
}

sim::RobotOptions FollowerRobot(const sim::Scenario& scenario,
                                const EigenspaceRunOptions& options) {
  sim::RobotOptions robot = scenario.robot;
  robot.motion_noise_v_frac = options.motion_noise;
  robot.motion_noise_omega_frac = options.motion_noise;
  return robot;
}

void Finalize(const EigenspaceRunOptions& options, const FollowerMetrics& metrics,
              const std::string& stop, bool arrived, EigenspaceRun* run) {
  const Pose2& end = run->leader_path.back();
  const Pose2& now = run->follower_path.empty() ? end : run->follower_path.back();
  run->final_error_m = now.DistanceTo(end);
  run->frames_after_convergence = metrics.frames;
  run->convergence_distance_m = metrics.converged_at_m;
  run->stops = metrics.stops;
  run->obstacle_stops = metrics.obstacle_stops;
  if (metrics.frames > 0) {
    run->lateral_rms_m = std::sqrt(metrics.lateral_sq / metrics.frames);
    run->localization_within_one = static_cast<double>(metrics.within_one) / metrics.frames;
    run->nearest_within_one = static_cast<double>(metrics.nearest_within_one) / metrics.frames;
  }
  if (!stop.empty()) {
    run->status = stop;
  } else if (!arrived) {
    run->status = "did not arrive";
  } else if (run->final_error_m > options.arrive_tolerance_m) {
    run->status = "arrived " + std::to_string(run->final_error_m) + " m from the end";
  } else {
    run->success = true;
    run->status = "arrived";
  }
}

// One follower frame: render, decide, command. Returns true when the follower has arrived.
bool FollowerFrame(sim::Simulation* sim, int robot, navigation::AppearanceFollower* follower,
                   sim::FaultyCamera* camera, const route::AppearanceRoute& route,
                   const std::vector<Pose2>& image_truth, const EigenspaceRunOptions& options,
                   const EigenspaceObserver& observer, FollowerMetrics* metrics,
                   EigenspaceRun* run) {
  const cv::Mat image = sim->Render(robot);
  const Pose2 truth = sim->robot(robot).pose();
  run->follower_path.push_back(truth);
  const navigation::FollowerStep step =
      follower->Update(camera->Apply(image, ToSeconds(sim->now_ns())), sim->robot(robot).odometry(),
                       route, sim->now_ns());
  metrics->Add(truth, step, image, route, image_truth, run->leader_path, options);
  if (observer) observer(step, truth);
  if (step.state == navigation::FollowerState::kArrived) return true;
  sim->SetCommand(robot, step.command);
  return false;
}

}  // namespace

SimSetup FollowSimSetup(const sim::Scenario& scenario, const EigenspaceRunOptions& options) {
  SimSetup setup;
  // What has changed since the teach (objects added or removed), as for a repeat.
  setup.world = sim::ApplyVariant(scenario.world, scenario.repeat_variant);
  setup.camera = scenario.camera;
  if (scenario.repeat_effects) setup.camera.effects = *scenario.repeat_effects;
  setup.robot = FollowerRobot(scenario, options);
  setup.start = StartPose(scenario, options);
  setup.seed = options.seed + 7919;
  return setup;
}

double FollowTimeoutS(const sim::Scenario& scenario, const EigenspaceRunOptions& options) {
  const double nominal = scenario.PathLength() / options.follower.steering.max_speed_mps +
                         scenario.PathLength() / scenario.teach_speed_mps + 30.0;
  return options.timeout_factor * nominal;
}

TaughtAppearance TeachAppearanceOnSimulator(const sim::Scenario& scenario,
                                            const EigenspaceRunOptions& options) {
  TaughtAppearance taught;
  navigation::AppearanceLeader leader(options.leader);
  taught.stored.image_width = scenario.camera.model.width;
  taught.stored.image_height = scenario.camera.model.height;
  taught.stored.low_width = options.leader.image.width;
  taught.stored.low_height = options.leader.image.height;
  sim::DriveOptions drive;
  drive.seed = options.seed;
  sim::DriveTaughtPath(scenario, drive, [&](const sim::DriveFrame& frame) {
    taught.leader_path.push_back(frame.truth);
    if (leader.Update(frame.image, frame.odometry)) {
      taught.image_truth.push_back(frame.truth);
      taught.stored.images.push_back(
          {leader.last_low().clone(), leader.distance_m(), frame.odometry, {}});
    }
  });
  taught.stored.complete = true;
  return taught;
}

EigenspaceRun RunEigenspaceFollow(const sim::Scenario& scenario,
                                  const EigenspaceRunOptions& options,
                                  const EigenspaceObserver& observer) {
  MAPLESS_CHECK(options.leader.incremental || !options.concurrent,
                "eigenspace run: following while the leader teaches needs incremental PCA");
  EigenspaceRun run;
  const double period = 1.0 / scenario.camera.rate_hz;
  navigation::AppearanceLeader leader(options.leader);
  navigation::AppearanceFollower follower(options.follower);
  sim::FaultyCamera faulty_camera(options.camera_faults, options.seed);
  route::AppearanceRouteChannel channel;
  std::vector<Pose2> image_truth;
  FollowerMetrics metrics;
  const double timeout_s = FollowTimeoutS(scenario, options);
  const std::uint64_t seed = options.seed;

  MAPLESS_CHECK(options.taught == nullptr || !options.concurrent,
                "eigenspace run: a stored route is followed after its teach, not concurrently");
  if (!options.concurrent) {
    if (options.taught != nullptr) {
      run.leader_path = options.taught->leader_path;
      image_truth = options.taught->image_truth;
      channel.Publish(
          navigation::BuildStoredAppearanceRoute(options.taught->stored, options.leader));
    } else {
      // Teach first (the scripted driver, clean), then follow in a world without the leader.
      sim::DriveOptions drive;
      drive.seed = seed;
      sim::DriveTaughtPath(scenario, drive, [&](const sim::DriveFrame& frame) {
        run.leader_path.push_back(frame.truth);
        if (leader.Update(frame.image, frame.odometry)) image_truth.push_back(frame.truth);
      });
      leader.Finish();
      channel.Publish(leader.Snapshot());
    }
    const std::shared_ptr<const route::AppearanceRoute> route = channel.Latest();
    run.route_images = route->size();
    const SimSetup setup = FollowSimSetup(scenario, options);
    sim::Simulation sim(setup.world, setup.camera, {}, setup.seed);
    const int robot = sim.AddRobot(setup.start, setup.robot);
    robot::FollowMethod method([&] { return route; }, options.follower);
    robot::SimLinkOptions link_options;
    link_options.period_s = period;
    link_options.timeout_s = timeout_s;
    link_options.camera_faults = options.camera_faults;
    link_options.fault_seed = options.seed;
    robot::SimLink link(sim, robot, link_options);
    // The objects added at follow time, for the obstacle watch's figures.
    const sim::World added = ObjectsAddedAtRepeat(scenario);
    bool was_blocked = false;
    const robot::LoopResult result = robot::RunLoop(
        method, link, BlockedLoop(options.max_blocked_s),
        [&](const robot::Observation& obs, const robot::Decision& decision) {
          const auto& step = decision.DetailAs<robot::FollowerDetail>()->step;
          const Pose2 truth = link.truth();
          const sim::World now = sim::WorldAt(added, ToSeconds(obs.t_ns));
          if (step.obstacle.blocked && !was_blocked && !now.objects.empty())
            ++run.stops_at_added_object;
          was_blocked = step.obstacle.blocked;
          if (!now.objects.empty()) {
            run.min_clearance_m =
                std::min(run.min_clearance_m,
                         sim::ClearanceTo(now, truth.x_m, truth.y_m) - scenario.robot.radius_m);
          }
          run.follower_path.push_back(truth);
          metrics.Add(truth, step, obs.image, *route, image_truth, run.leader_path, options);
          if (observer) observer(step, truth);
          return true;
        });
    const bool arrived = result.finished;
    run.collided = sim.collided(robot);
    run.learned = method.follower().learned();
    run.used_views = method.follower().used_views();
    Finalize(options, metrics, arrived ? std::string() : result.reason, arrived, &run);
    return run;
  }

  // Concurrent: both robots in one world; the follower starts once the leader has stored
  // follower_starts_after_images images, and uses each snapshot the leader publishes.
  sim::Simulation sim(scenario.world, scenario.camera, {}, seed);
  const int lead = sim.AddRobot(scenario.teach_start, scenario.robot);
  sim::ScriptedDriver driver(scenario.teach_start, scenario.teach_path, scenario.teach_speed_mps);
  int follow = -1;
  bool leader_done = false;
  std::string stop;
  bool arrived = false;
  while (true) {
    if (!leader_done) {
      const Pose2 truth = sim.robot(lead).pose();
      run.leader_path.push_back(truth);
      if (leader.Update(sim.Render(lead), sim.robot(lead).odometry())) {
        image_truth.push_back(truth);
        channel.Publish(leader.Snapshot());
      }
      if (driver.done()) {
        leader.Finish();
        channel.Publish(leader.Snapshot());
        leader_done = true;
        sim.PlaceRobot(lead, Pose2{1000.0, 1000.0, 0.0});  // the leader leaves the scene
      } else {
        sim.SetCommand(lead, driver.Update(truth));
      }
    }
    if (follow < 0 && leader.images() >= options.follower_starts_after_images) {
      follow = sim.AddRobot(StartPose(scenario, options), FollowerRobot(scenario, options));
    }
    if (follow >= 0) {
      arrived = FollowerFrame(&sim, follow, &follower, &faulty_camera, *channel.Latest(),
                              image_truth, options, observer, &metrics, &run);
      if (arrived) break;
    }
    sim.Advance(period);
    stop = SimulationStop(sim, lead, timeout_s);
    if (stop.empty() && follow >= 0) stop = SimulationStop(sim, follow, timeout_s);
    if (!stop.empty()) break;
  }
  run.route_images = leader.images();
  run.collided = sim.collided(lead) || (follow >= 0 && sim.collided(follow));
  Finalize(options, metrics, stop, arrived, &run);
  return run;
}

std::vector<EigenspaceEntry> EigenspaceSuiteEntries() {
  std::vector<EigenspaceEntry> entries;
  for (const char* scenario : {"office_aliasing", "outdoor_70m"}) {
    for (const char* experiment : {"on-route", "off-route-left", "off-route-right", "batch-pca",
                                   "no-markov", "concurrent"}) {
      entries.push_back({scenario, experiment});
    }
  }
  entries.push_back({"obstacle_box_office", "on-route"});
  // Issue 21, recovery: route images whose carts are gone, with and without it.
  entries.push_back({"route_images_gone_office", "on-route"});
  entries.push_back({"route_images_gone_office", "no-recovery"});
  return entries;
}

EigenspaceRunOptions EigenspaceEntryOptions(const EigenspaceEntry& entry, std::uint64_t seed) {
  EigenspaceRunOptions options;
  options.seed = seed;
  // Each run's follower slips: its commands are executed with 10% noise (drawn per command from
  // the run's seed), so that the runs differ.
  options.motion_noise = 0.1;
  const std::string& e = entry.experiment;
  // Fig. 7-8: starts off the route, 0.5 m to the side, 1 m behind, rotated by 20 degrees.
  if (e == "off-route-left") {
    options.start_offset = Pose2{-1.0, 0.5, DegToRad(-20.0)};
  } else if (e == "off-route-right") {
    options.start_offset = Pose2{-1.0, -0.5, DegToRad(20.0)};
  } else if (e == "batch-pca") {
    options.leader.incremental = false;
  } else if (e == "no-markov") {
    options.follower.use_markov = false;
  } else if (e == "concurrent") {
    options.concurrent = true;
  } else if (e == "no-recovery") {
    options.follower.recover_images = 0;
    options.follower.carry_on.max_distance_m = 0.0;
  } else {
    MAPLESS_CHECK(e == "on-route", "eigenspace suite: unknown experiment '" << e << "'");
  }
  return options;
}

EigenspaceEntryResult RunEigenspaceEntry(const EigenspaceEntry& entry, int runs, std::uint64_t seed,
                                         const EigenspaceObserver& first_run, bool learn) {
  MAPLESS_CHECK(runs >= 1, "eigenspace suite: runs = " << runs << "; must be >= 1");
  const sim::Scenario scenario = sim::LoadScenario(entry.scenario);
  EigenspaceEntryResult result;
  result.scenario = entry.scenario;
  result.controller = "subwindow";
  result.experiment = entry.experiment;
  result.runs = runs;
  double final_sq = 0.0;
  double lateral_sq = 0.0;
  std::vector<double> finals;
  // learn: one route for all runs (taught as the first run's leader teaches it), each run
  // learning into it for the next (not while the leader teaches).
  const EigenspaceRunOptions first = EigenspaceEntryOptions(entry, seed);
  const bool one_route = learn && !first.concurrent;
  TaughtAppearance taught;
  if (one_route) taught = TeachAppearanceOnSimulator(scenario, first);
  for (int r = 0; r < runs; ++r) {
    EigenspaceRunOptions options =
        EigenspaceEntryOptions(entry, seed + static_cast<std::uint64_t>(r));
    if (one_route) {
      options.taught = &taught;
      options.follower.learn = true;
    }
    const EigenspaceRun run =
        RunEigenspaceFollow(scenario, options, r == 0 ? first_run : EigenspaceObserver{});
    if (one_route && run.success) {
      result.learned += static_cast<int>(run.learned.size());
      ApplyAppearanceVisit(&taught.stored, run.used_views, run.learned,
                           options.follower.experiences);
    }
    if (result.reference_path.empty()) result.reference_path = run.leader_path;
    result.paths.push_back(run.follower_path);
    result.successes += run.success;
    result.collisions += run.collided;
    if (!run.success) {
      result.failures.push_back("seed " + std::to_string(seed + static_cast<std::uint64_t>(r)) +
                                ": " + run.status);
    }
    finals.push_back(run.final_error_m);
    final_sq += run.final_error_m * run.final_error_m;
    lateral_sq += run.lateral_rms_m * run.lateral_rms_m;
    result.lateral_rms_m_max = std::max(result.lateral_rms_m_max, run.lateral_rms_m);
    result.localization_within_one += run.localization_within_one / runs;
    result.nearest_within_one += run.nearest_within_one / runs;
    result.stops += run.stops;
    if (run.obstacle_stops > 0) ++result.obstacle_stops;
    if (run.stops_at_added_object > 0) ++result.stops_at_added_object;
    result.min_clearance_m = std::min(result.min_clearance_m, run.min_clearance_m);
  }
  result.final_error_m_rms = std::sqrt(final_sq / runs);
  result.lateral_rms_m = std::sqrt(lateral_sq / runs);
  double mean = 0.0;
  for (const double f : finals) mean += f / runs;
  double var = 0.0;
  for (const double f : finals) var += (f - mean) * (f - mean) / runs;
  result.final_error_m_std = std::sqrt(var);
  return result;
}

}  // namespace mapless::eval
