#include "demo_runs.h"

#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "cli_common.h"
#include "interrupt.h"
#include "mapless/core/check.h"
#include "mapless/eval/eigenspace.h"
#include "mapless/eval/potential.h"
#include "mapless/report/pictures.h"

namespace mapless::app {
namespace {

report::PlotSpec CommandsPlot(const std::vector<double>& t, const std::vector<double>& v,
                              const std::vector<double>& omega) {
  report::PlotSpec p{"Commands over time", "time (s)", "v (m/s), omega (rad/s)", {}, 640, 240};
  p.series.push_back({t, v, "#1f77b4", "v (m/s)", false, false});
  p.series.push_back({t, omega, "#ff7f0e", "omega (rad/s)", false, false});
  return p;
}

// Frames at 20%, 50% and 80% of `expected` frames: the chosen frames of the pictures.
bool Chosen(int frame, std::size_t expected) {
  for (double f : {0.2, 0.5, 0.8})
    if (frame == static_cast<int>(f * static_cast<double>(expected))) return true;
  return false;
}

}  // namespace

DemoResult DemoRepeat(const sim::Scenario& scenario, const eval::TaughtRoute& taught,
                      std::uint64_t seed, const std::string& log_path) {
  eval::RepeatRunOptions options;
  options.seed = seed;
  options.repeat.sloped.max_speed_mps =
      eval::RepeatSpeedFor(scenario, options.max_repeat_speed_mps);
  JsonLines log(log_path, /*in_place=*/true);
  DemoResult out;
  std::vector<double> t, v, omega, slope_x, slope_y;
  int frame = 0;
  const double dt = 1.0 / scenario.camera.rate_hz;
  const eval::RepeatRun run = eval::RepeatOnSimulator(
      scenario, taught, options,
      [&](const Pose2& pose, const cv::Mat& image, const navigation::RepeatStep& s) {
        ThrowIfInterrupted();
        nlohmann::json j{{"frame", frame},
                         {"x_m", pose.x_m},
                         {"y_m", pose.y_m},
                         {"destination", s.destination},
                         {"matches", s.matches},
                         {"std_ratio", s.switching.std_ratio},
                         {"slope_x", s.sloped.slope_x},
                         {"slope_y", s.sloped.slope_y},
                         {"v_mps", s.command.v_mps},
                         {"omega_radps", s.command.omega_radps},
                         {"status", navigation::RepeatStatusName(s.status)}};
        if (s.local_scale.ok) j["local_scale"] = s.local_scale.ratio;
        log.Write(j);
        t.push_back(frame * dt);
        v.push_back(s.command.v_mps);
        omega.push_back(s.command.omega_radps);
        slope_x.push_back(s.sloped.slope_x);
        slope_y.push_back(s.sloped.slope_y);
        const auto& keyframes = taught.route->keyframes;
        if (Chosen(frame, taught.path.size()) && s.destination >= 0 &&
            s.destination < static_cast<int>(keyframes.size())) {
          out.section.pictures.push_back(
              {report::MatchPicture(
                   image, keyframes[static_cast<std::size_t>(s.destination)].thumbnail,
                   s.current_px, s.destination_px,
                   "frame " + std::to_string(frame) + ", keyframe " +
                       std::to_string(s.destination) + ": " + std::to_string(s.matches) +
                       " matches, slopes " + Fixed(s.sloped.slope_x, 2) + " / " +
                       Fixed(s.sloped.slope_y, 2)),
               "frame " + std::to_string(frame) + " (left) and keyframe " +
                   std::to_string(s.destination) + " (right)"});
        }
        ++frame;
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
  s.plots = {err, CommandsPlot(t, v, omega)};
  report::PlotSpec slopes{
      "Funnel-lane slopes (Kassir et al., Eq. 6-7)", "time (s)", "slope", {}, 640, 220};
  slopes.series.push_back({t, slope_x, "#9467bd", "slope x", false, false});
  slopes.series.push_back({t, slope_y, "#8c564b", "slope y", true, false});
  s.plots.push_back(slopes);
  s.pictures_caption =
      "Chosen frames: the current image next to its destination keyframe (its "
      "stored thumbnail), with the matched features joined.";
  out.success = run.success;
  out.status = run.status;
  out.row = {"teach & repeat (sloped funnel lane)", scenario.name, run.success ? "yes" : "no",
             Fixed(run.final_error_m, 3), "lateral RMS " + Fixed(run.lateral_rms_m, 3) + " m"};
  return out;
}

DemoResult DemoEigenspace(const std::string& scenario_name, std::uint64_t seed) {
  const sim::Scenario scenario = sim::LoadScenario(scenario_name);
  eval::EigenspaceRunOptions options =
      eval::EigenspaceEntryOptions({scenario_name, "concurrent"}, seed);
  DemoResult out;
  std::vector<double> t, v, omega, index, probability;
  std::vector<std::vector<float>> beliefs;
  const double dt = 1.0 / scenario.camera.rate_hz;
  int frame = 0;
  const eval::EigenspaceRun run = eval::RunEigenspaceFollow(
      scenario, options, [&](const navigation::FollowerStep& step, const Pose2&) {
        ThrowIfInterrupted();
        t.push_back(frame * dt);
        v.push_back(step.command.v_mps);
        omega.push_back(step.command.omega_radps);
        index.push_back(step.index >= 0 ? step.index : std::nan(""));
        probability.push_back(step.index >= 0 ? step.probability : std::nan(""));
        beliefs.push_back(step.belief);
        ++frame;
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
  report::PlotSpec loc{"Localization over time", "time (s)", "route image", {}, 640, 240};
  loc.series.push_back({t, index, "#1f77b4", "localized route image", false, true});
  report::PlotSpec prob{"Belief mass around the estimate", "time (s)", "probability", {}, 640, 200};
  prob.series.push_back({t, probability, "#2ca02c", "probability", false, false});
  s.plots = {err, CommandsPlot(t, v, omega), loc, prob};
  s.pictures.push_back({report::BeliefPicture(beliefs, {}), "the belief over time"});
  s.pictures_caption =
      "The Markov belief over the route images (upwards) against time (to the "
      "right); brighter is more likely. The route grows while the leader teaches.";
  out.success = run.success;
  out.status = run.status;
  out.row = {"eigenspace follower (leader still teaching)", scenario.name,
             run.success ? "yes" : "no", Fixed(run.final_error_m, 3),
             "localized within 1 image: " + Fixed(100.0 * run.localization_within_one, 0) + "%"};
  return out;
}

DemoResult DemoPotential(const std::string& scenario_name, std::uint64_t seed) {
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
  std::vector<double> t, v, omega, plane;
  const double dt = 1.0 / scenario.camera.rate_hz;
  int frame = 0;
  const eval::PotentialRun run = eval::RunPotential(
      scenario, calibration, options,
      [&](const Pose2&, const cv::Mat& image, const navigation::PotentialStep& step) {
        ThrowIfInterrupted();
        t.push_back(frame * dt);
        v.push_back(step.command.v_mps);
        omega.push_back(step.command.omega_radps);
        plane.push_back(step.plane_found ? step.plane_fraction : std::nan(""));
        if ((frame == 15 || frame == 60 || frame == 120) && !step.plane_mask.empty()) {
          out.section.pictures.push_back(
              {report::PlanePicture(image, step.plane_mask, step.theta_rad,
                                    "frame " + std::to_string(frame) +
                                        (step.leg == 0 ? ", to the destination" : ", homing") +
                                        ", force " + Fixed(step.theta_rad * 180.0 / kPi, 0) +
                                        " deg"),
               "frame " + std::to_string(frame)});
        }
        ++frame;
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
  report::PlotSpec frac{"Dominant plane", "time (s)", "fraction of the image", {}, 640, 200};
  frac.series.push_back({t, plane, "#2ca02c", "plane fraction", false, false});
  s.plots = {CommandsPlot(t, v, omega), frac};
  s.pictures_caption =
      "Chosen frames: the dominant plane (green: free ground; red: obstacles) "
      "and the direction of the control force (arrow).";
  out.success = run.success;
  out.status = run.status;
  out.row = {"visual potential (destination and home)", scenario.name, run.success ? "yes" : "no",
             Fixed(run.final_error_m, 3),
             Fixed(run.duration_s, 1) + " s, " + std::to_string(run.no_plane_frames) +
                 " frames without a plane"};
  return out;
}

}  // namespace mapless::app
