// `mapless demo`: the main job. On the built-in simulator: teach a route by driving it (camera
// frames, poses, the route store), then repeat it with the sloped funnel lane from a perturbed
// start with motion and image noise, and draw both paths from above.
#include <spdlog/spdlog.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "cli_common.h"
#include "interrupt.h"
#include "mapless/eval/teach_repeat.h"
#include "mapless/io/atomic_file.h"
#include "mapless/io/output_dir.h"
#include "mapless/route/route_store.h"
#include "mapless/viz/topdown.h"

namespace mapless::app {

void AddDemoCommand(CLI::App* app) {
  struct Args {
    std::string scenario = "narrow_room_sharp_turn";
    std::string out = "demo_out";
    std::string config;
    std::uint64_t seed = 1;
  };
  auto args = std::make_shared<Args>();
  CLI::App* demo = app->add_subcommand("demo",
                                       "Teach a route on the built-in simulator and repeat it; "
                                       "write frames, the route and a top-down picture");
  demo->add_option("--scenario", args->scenario, "Built-in scenario name or YAML file")
      ->capture_default_str();
  demo->add_option("--out", args->out, "Output directory")->capture_default_str();
  demo->add_option("--seed", args->seed, "Seed of motion and image noise")
      ->capture_default_str()
      ->check(SeedCheck());
  demo->add_option("--config", args->config, "Run configuration YAML (see config/default.yaml)");
  demo->callback([args] {
    RefuseOutputOverInputs(args->out, "--out", {args->scenario, args->config});
    const sim::Scenario scenario = sim::LoadScenario(args->scenario);
    sim::DriveOptions options = LoadDriveOptions(args->config);
    options.seed = args->seed;
    // An earlier demo's output (it has teach/frames.csv, even when that demo was killed) is
    // replaced when this demo is done; any other directory with content is refused.
    io::OutputDirectory out_dir(args->out, /*replace=*/true, "demo's output", "teach/frames.csv");
    StopCleanlyOnInterrupt();
    const std::filesystem::path out(out_dir.path());
    spdlog::info("demo: teaching route '{}' ({:.1f} m) on the simulator", scenario.name,
                 scenario.PathLength());
    const sim::DriveSummary summary = DriveToDirectory(scenario, options, (out / "teach").string());
    spdlog::info("demo: teach drive: {} frames, {:.1f} s, {:.2f} m: {}", summary.frames,
                 summary.duration_s, summary.distance_m, summary.status);
    if (!summary.completed)
      throw RunFailed("demo: teach drive did not complete: " + summary.status);

    // The route store, written keyframe by keyframe as the teach goes.
    const std::string route_dir = (out / "route").string();
    route::RouteWriter writer(route_dir, "orb", scenario.camera.model.width,
                              scenario.camera.model.height);
    const eval::TaughtRoute taught = eval::TeachOnSimulator(scenario, navigation::TeachOptions{},
                                                            [&](const route::Keyframe& kf) {
                                                              ThrowIfInterrupted();
                                                              writer.Append(kf);
                                                            });
    writer.Finish();
    spdlog::info("demo: route of {} keyframes in {}", taught.route->keyframes.size(), route_dir);

    // Repeat with the sloped funnel lane, decisions logged as JSON lines.
    eval::RepeatRunOptions run_options;
    run_options.seed = args->seed;
    const double speed = eval::RepeatSpeedFor(scenario, run_options.max_repeat_speed_mps);
    run_options.repeat.sloped.max_speed_mps = speed;
    JsonLines log((out / "repeat.jsonl").string(), /*in_place=*/true);
    int frame = 0;
    const eval::RepeatRun run = eval::RepeatOnSimulator(
        scenario, taught, run_options,
        [&](const Pose2& pose, const cv::Mat&, const navigation::RepeatStep& s) {
          ThrowIfInterrupted();
          nlohmann::json j{{"frame", frame++},
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
        });
    const cv::Mat top =
        viz::DrawTopDown(sim::ApplyVariant(scenario.world, scenario.repeat_variant),
                         {{taught.path, cv::Scalar(30, 30, 220), "taught"},
                          {run.path, cv::Scalar(40, 160, 40), "repeated (sloped funnel lane)"}},
                         scenario.destinations);
    io::WriteImageAtomic((out / "topdown.png").string(), top);
    nlohmann::json j{{"scenario", scenario.name},
                     {"keyframes", taught.route->keyframes.size()},
                     {"success", run.success},
                     {"status", run.status},
                     {"final_error_m", run.final_error_m},
                     {"lateral_rms_m", run.lateral_rms_m},
                     {"repeat_duration_s", run.duration_s}};
    io::WriteFileAtomic((out / "summary.json").string(), j.dump(2) + "\n");
    out_dir.Commit();
    spdlog::info("demo: repeat: {}; ended {:.2f} m from the taught end, lateral RMS {:.2f} m",
                 run.status, run.final_error_m, run.lateral_rms_m);
    spdlog::info(
        "demo: wrote {0}/topdown.png, {0}/teach/ (frames, poses), {0}/route/, {0}/repeat.jsonl, "
        "{0}/summary.json",
        args->out);
    if (!run.success) throw RunFailed("demo: the repeat did not succeed: " + run.status);
  });
}

}  // namespace mapless::app
