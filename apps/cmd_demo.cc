// `mapless demo`: the main job. On the built-in simulator, drive a taught route through a scenario
// and write the camera frames and a top-down picture of the route.
#include <spdlog/spdlog.h>

#include "cli_common.h"

namespace mapless::app {

void AddDemoCommand(CLI::App* app) {
  struct Args {
    std::string scenario = "narrow_room_sharp_turn";
    std::string out = "demo_out";
    std::string config;
    std::uint64_t seed = 1;
  };
  auto args = std::make_shared<Args>();
  CLI::App* demo = app->add_subcommand(
      "demo", "Drive a taught route on the built-in simulator; write frames and a top-down picture");
  demo->add_option("--scenario", args->scenario, "Built-in scenario name or YAML file")
      ->capture_default_str();
  demo->add_option("--out", args->out, "Output directory")->capture_default_str();
  demo->add_option("--seed", args->seed, "Seed of motion and image noise")->capture_default_str();
  demo->add_option("--config", args->config, "Run configuration YAML (see config/default.yaml)");
  demo->callback([args] {
    const sim::Scenario scenario = sim::LoadScenario(args->scenario);
    sim::DriveOptions options = LoadDriveOptions(args->config);
    options.seed = args->seed;
    spdlog::info("demo: teaching route '{}' ({:.1f} m) on the simulator", scenario.name,
                 scenario.PathLength());
    const sim::DriveSummary summary = DriveToDirectory(scenario, options, args->out);
    spdlog::info("demo: {} frames, {:.1f} s, {:.2f} m driven: {}", summary.frames, summary.duration_s,
                 summary.distance_m, summary.status);
    spdlog::info("demo: wrote {0}/topdown.png, {0}/frames/, {0}/groundtruth.tum, {0}/summary.json",
                 args->out);
    if (!summary.completed) throw RunFailed("demo did not complete: " + summary.status);
  });
}

}  // namespace mapless::app
