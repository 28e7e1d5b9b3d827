#include "mapless/run/demo.h"

#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "mapless/core/check.h"
#include "mapless/eval/eigenspace.h"
#include "mapless/eval/potential.h"
#include "mapless/run/decision_log.h"
#include "mapless/run/traces.h"

namespace mapless::run {

DemoResult DemoRepeat(const sim::Scenario& scenario, const eval::TaughtRoute& taught,
                      std::uint64_t seed, const JsonSink& log,
                      const std::function<void()>& each_frame) {
  eval::RepeatRunOptions options;
  options.seed = seed;
  options.repeat.sloped.max_speed_mps =
      eval::RepeatSpeedFor(scenario, options.max_repeat_speed_mps);
  options.wrap_link = LogDecisions("repeat", log);
  DemoResult out;
  RepeatTrace trace(taught, 1.0 / scenario.camera.rate_hz);
  const eval::RepeatRun run = eval::RepeatOnSimulator(
      scenario, taught, options,
      [&](const Pose2&, const cv::Mat& image, const navigation::RepeatStep& s) {
        if (each_frame) each_frame();
        trace.Step(image, s);
      });
  RunSection& s = out.section;
  s.title = "Teach & repeat: the sloped funnel lane (" + scenario.name + ")";
  s.slug = "repeat";
  s.summary = "The route was taught by driving it (" +
              std::to_string(taught.route->keyframes.size()) +
              " keyframes), then repeated from a perturbed start with 10% motion noise and image "
              "noise: " +
              run.status + "; ended " + Fixed(run.final_error_m, 2) +
              " m from the taught end, lateral RMS " + Fixed(run.lateral_rms_m, 3) + " m.";
  s.world = sim::ApplyVariant(scenario.world, scenario.repeat_variant);
  s.markers = scenario.destinations;
  s.paths = {{taught.path, "#d62728", "taught"}, {run.path, "#2ca02c", "repeated"}};
  report::PlotSpec err{"Error along the path",
                       "distance driven (m)",
                       "to the taught path (m, left +)",
                       {},
                       640,
                       240};
  err.series.push_back(ErrorAlongPath(taught.path, run.path, "#2ca02c", "repeated"));
  s.plots = {err};
  trace.AddTo(&s);
  out.success = run.success;
  out.status = run.status;
  out.row = {"teach & repeat (sloped funnel lane)",
             scenario.name,
             run.success ? "yes" : "no",
             Fixed(run.final_error_m, 3),
             "lateral RMS " + Fixed(run.lateral_rms_m, 3) + " m",
             "completes the route, no collision, ends within " +
                 Fixed(options.success_radius_m, 1) + " m of the taught end"};
  return out;
}

DemoResult DemoEigenspace(const std::string& scenario_name, std::uint64_t seed,
                          const std::function<void()>& each_frame) {
  const sim::Scenario scenario = sim::LoadScenario(scenario_name);
  eval::EigenspaceRunOptions options =
      eval::EigenspaceEntryOptions({scenario_name, "concurrent"}, seed);
  DemoResult out;
  EigenspaceTrace trace(1.0 / scenario.camera.rate_hz);
  const eval::EigenspaceRun run = eval::RunEigenspaceFollow(
      scenario, options, [&](const navigation::FollowerStep& step, const Pose2&) {
        if (each_frame) each_frame();
        trace.Step(step);
      });
  RunSection& s = out.section;
  s.title = "Eigenspace follower while the leader teaches (" + scenario.name + ")";
  s.slug = "eigenspace";
  s.summary =
      "The leader drives the route and adds each route image to an incremental eigenspace "
      "(Payá et al.); the follower starts after " +
      std::to_string(options.follower_starts_after_images) +
      " images and localizes itself with Markov localization on the growing route: " + run.status +
      "; " + std::to_string(run.route_images) + " route images, ended " +
      Fixed(run.final_error_m, 2) + " m from the route end, lateral RMS " +
      Fixed(run.lateral_rms_m, 3) + " m, localized within one image on " +
      Fixed(100.0 * run.localization_within_one, 0) + "% of the frames.";
  s.world = scenario.world;
  s.paths = {{run.leader_path, "#d62728", "leader"}, {run.follower_path, "#1f77b4", "follower"}};
  report::PlotSpec err{"Error along the path",
                       "distance driven (m)",
                       "to the leader's path (m, left +)",
                       {},
                       640,
                       240};
  err.series.push_back(ErrorAlongPath(run.leader_path, run.follower_path, "#1f77b4", "follower"));
  s.plots = {err};
  trace.AddTo(&s);
  out.success = run.success;
  out.status = run.status;
  out.row = {"eigenspace follower (leader still teaching)",
             scenario.name,
             run.success ? "yes" : "no",
             Fixed(run.final_error_m, 3),
             "localized within 1 image: " + Fixed(100.0 * run.localization_within_one, 0) + "%",
             "arrives, no collision, within " + Fixed(options.arrive_tolerance_m, 1) +
                 " m of the route's end"};
  return out;
}

DemoResult DemoPotential(const std::string& scenario_name, std::uint64_t seed,
                         const std::function<void()>& each_frame) {
  const sim::Scenario scenario = sim::LoadScenario(scenario_name);
  MAPLESS_CHECK(!scenario.destinations.empty(), scenario_name << " has no destination");
  eval::PotentialRunOptions options;
  options.motion_noise_frac = 0.1;
  options.image_noise_sigma = 2.0;
  options.destination = scenario.destinations[0];
  options.homing = true;
  options.seed = seed;
  options.nav.noise_seed = seed;
  const navigation::PlanarFlowCalibration calibration =
      eval::CalibrateOnSimulator(scenario, options.nav);
  DemoResult out;
  PotentialTrace trace(1.0 / scenario.camera.rate_hz);
  const eval::PotentialRun run = eval::RunPotential(
      scenario, calibration, options,
      [&](const Pose2&, const cv::Mat& image, const navigation::PotentialStep& step) {
        if (each_frame) each_frame();
        trace.Step(image, step);
      });
  RunSection& s = out.section;
  s.title = "Visual potential: to a destination and home (" + scenario.name + ")";
  s.slug = "potential";
  s.summary =
      "The dominant plane of the optical flow (Ohnishi & Imiya) is the free ground; its "
      "potential field, with the destination's attraction, steers the robot there and "
      "back: " +
      run.status + "; ended " + Fixed(run.final_error_m, 2) + " m from the start, " +
      Fixed(run.duration_s, 1) + " s.";
  s.world = scenario.world;
  s.markers = {*options.destination};
  s.paths = {{run.path, "#9467bd", "driven (to the star and back)"}};
  trace.AddTo(&s);
  out.success = run.success;
  out.status = run.status;
  out.row = {"visual potential (destination and home)",
             scenario.name,
             run.success ? "yes" : "no",
             Fixed(run.final_error_m, 3),
             Fixed(run.duration_s, 1) + " s, " + std::to_string(run.no_plane_frames) +
                 " frames without a plane",
             "reaches the destination and comes home, no collision, within " +
                 Fixed(options.success_radius_m, 1) + " m"};
  return out;
}

}  // namespace mapless::run
