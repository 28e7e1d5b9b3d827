// `mapless sim list | render | drive`: the built-in simulator from the command line.
#include <spdlog/spdlog.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>

#include "cli_common.h"
#include "interrupt.h"
#include "mapless/core/check.h"
#include "mapless/io/atomic_file.h"
#include "mapless/io/journal.h"
#include "mapless/io/output_dir.h"
#include "mapless/io/tum.h"
#include "mapless/sim/generator.h"
#include "mapless/sim/world.h"
#include "mapless/viz/topdown.h"
#include "robot_run.h"

namespace mapless::app {

sim::DriveSummary DriveToDirectory(const sim::Scenario& scenario, const sim::DriveOptions& options,
                                   const std::string& out_dir) {
  const std::filesystem::path dir(out_dir);
  io::MakeDirectories((dir / "frames").string());
  std::vector<io::StampedPose> truth;
  std::vector<io::StampedPose> odom;
  // Journals, written frame by frame after the frame's image: a recording killed at any moment
  // keeps every frame it finished, listed and with its poses (see io/journal.h).
  io::JournalFile frames_csv((dir / "frames.csv").string());
  io::JournalFile truth_tum((dir / "groundtruth.tum").string());
  io::JournalFile odom_tum((dir / "odometry.tum").string());
  frames_csv.Append("index,t_s,file");
  truth_tum.Append(io::kTumHeader);
  odom_tum.Append(io::kTumHeader);
  const sim::DriveSummary summary =
      sim::DriveTaughtPath(scenario, options, [&](const sim::DriveFrame& f) {
        ThrowIfInterrupted();
        char name[32];
        std::snprintf(name, sizeof(name), "%06d.png", f.index);
        io::WriteImageAtomic((dir / "frames" / name).string(), f.image);
        truth.push_back({f.t_ns, f.truth});
        odom.push_back({f.t_ns, f.odometry});
        char row[96];
        std::snprintf(row, sizeof(row), "%d,%.3f,frames/%s", f.index, ToSeconds(f.t_ns), name);
        frames_csv.Append(row);
        truth_tum.Append(io::FormatTumLine(truth.back()));
        odom_tum.Append(io::FormatTumLine(odom.back()));
      });
  frames_csv.Sync();
  truth_tum.Sync();
  odom_tum.Sync();
  std::vector<Pose2> truth_poses;
  std::vector<Pose2> odom_poses;
  for (const auto& p : truth) truth_poses.push_back(p.pose);
  for (const auto& p : odom) odom_poses.push_back(p.pose);
  const cv::Mat top =
      viz::DrawTopDown(scenario.world,
                       {{truth_poses, cv::Scalar(30, 30, 220), "taught path (ground truth)"},
                        {odom_poses, cv::Scalar(200, 120, 30), "wheel odometry"}},
                       scenario.destinations);
  io::WriteImageAtomic((dir / "topdown.png").string(), top);
  nlohmann::json j;
  j["scenario"] = scenario.name;
  j["seed"] = options.seed;
  j["frames"] = summary.frames;
  j["duration_s"] = summary.duration_s;
  j["distance_m"] = summary.distance_m;
  j["completed"] = summary.completed;
  j["collided"] = summary.collided;
  j["status"] = summary.status;
  io::WriteFileAtomic((dir / "summary.json").string(), j.dump(2) + "\n");
  return summary;
}

namespace {

// `mapless sim generate`: a world drawn from a seed, written as a scenario file.
void AddGenerateCommand(CLI::App* simcmd) {
  struct GenerateArgs {
    sim::GenerateOptions options;
    std::string out;
    bool overwrite = false;
  };
  auto a = std::make_shared<GenerateArgs>();
  CLI::App* cmd = simcmd->add_subcommand(
      "generate", "Write a world drawn from a seed as a scenario file (docs/simulator.md)");
  cmd->add_option("--seed", a->options.seed, "The world's seed")
      ->capture_default_str()
      ->check(SeedCheck());
  std::string kinds;
  for (const std::string& k : sim::GeneratorKinds()) kinds += (kinds.empty() ? "" : ", ") + k;
  cmd->add_option("--kind", a->options.kind, "One of " + kinds + " (default: drawn from the seed)")
      ->check(CLI::IsMember(sim::GeneratorKinds()));
  cmd->add_option("--obstacle-share", a->options.obstacle_share,
                  "Share of seeds whose world gets an object on the path after the teach")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1.0));
  cmd->add_option("--out", a->out, "The scenario file to write (.yaml)")->required();
  cmd->add_flag("--overwrite", a->overwrite, "Replace --out when it exists");
  cmd->callback([a] {
    RefuseOutputOverInputs(a->out, "--out", {});
    if (!a->overwrite && std::filesystem::exists(a->out))
      throw InputError("--out " + a->out + ": exists (--overwrite replaces it)");
    const std::string text = sim::GenerateScenarioYaml(a->options);
    const sim::Scenario scenario = sim::ParseScenario(text, a->out, "");  // checks what it wrote
    io::WriteFileAtomic(a->out, text);
    spdlog::info("wrote {}: {}", a->out, scenario.description);
  });
}

}  // namespace

void AddSimCommands(CLI::App* app) {
  CLI::App* simcmd =
      app->add_subcommand("sim", "The built-in simulator: scenarios, renders, drives");
  simcmd->require_subcommand(1);

  CLI::App* list =
      simcmd->add_subcommand("list", "Print the built-in scenario names, one per line");
  list->callback([] {
    for (const auto& name : sim::BuiltinScenarioNames()) std::cout << name << "\n";
  });

  struct RenderArgs {
    std::string scenario;
    std::string pose;
    std::string out;
    std::uint64_t seed = 1;
    bool repeat_variant = false;
  };
  auto render_args = std::make_shared<RenderArgs>();
  CLI::App* render = simcmd->add_subcommand("render", "Render what the camera sees at one pose");
  render->add_option("--scenario", render_args->scenario, "Built-in scenario name or YAML file")
      ->required();
  render->add_option("--pose", render_args->pose, "Robot pose X,Y,THETA_DEG (metres, degrees)")
      ->required();
  render->add_option("--out", render_args->out, "Output image file (.png)")->required();
  render
      ->add_option("--seed", render_args->seed,
                   "Seed of the image noise (when the scenario has any)")
      ->check(SeedCheck());
  render->add_flag("--repeat-variant", render_args->repeat_variant,
                   "Render the world as the repeat phase sees it (objects removed or moved)");
  render->callback([render_args] {
    RefuseOutputOverInputs(render_args->out, "--out", {render_args->scenario});
    const sim::Scenario scenario = sim::LoadScenario(render_args->scenario);
    const Pose2 pose = ParsePoseDeg(render_args->pose, "--pose");
    if (std::abs(pose.x_m) > sim::kMaxWorldCoordinateM ||
        std::abs(pose.y_m) > sim::kMaxWorldCoordinateM) {
      throw InputError("--pose " + render_args->pose + ": beyond " +
                       std::to_string(static_cast<int>(sim::kMaxWorldCoordinateM)) +
                       " m from the origin");
    }
    const sim::World world = render_args->repeat_variant
                                 ? sim::ApplyVariant(scenario.world, scenario.repeat_variant)
                                 : scenario.world;
    sim::CameraSpec camera = scenario.camera;
    if (render_args->repeat_variant && scenario.repeat_effects)
      camera.effects = *scenario.repeat_effects;
    sim::Simulation s(world, camera, sim::SimulationOptions{}, render_args->seed);
    s.AddRobot(pose, scenario.robot);
    io::WriteImageAtomic(render_args->out, s.Render(0));
    spdlog::info("wrote {} ({}x{})", render_args->out, scenario.camera.model.width,
                 scenario.camera.model.height);
  });

  AddGenerateCommand(simcmd);

  struct DriveArgs {
    std::string scenario;
    std::string out;
    std::string config;
    std::uint64_t seed = 1;
    bool overwrite = false;
  };
  auto drive_args = std::make_shared<DriveArgs>();
  AddSimServeCommand(simcmd);

  CLI::App* drive = simcmd->add_subcommand(
      "drive", "Drive a scenario's taught path; write frames, poses (TUM) and a top-down picture");
  drive->add_option("--scenario", drive_args->scenario, "Built-in scenario name or YAML file")
      ->required();
  drive->add_option("--out", drive_args->out, "Output directory")->required();
  drive->add_option("--seed", drive_args->seed, "Seed of motion, odometry and image noise")
      ->check(SeedCheck());
  drive->add_option("--config", drive_args->config,
                    "Run configuration YAML (see config/default.yaml)");
  drive->add_flag("--overwrite", drive_args->overwrite,
                  "Replace what --out holds (the old content stays until the drive is done)");
  drive->callback([drive_args] {
    RefuseOutputOverInputs(drive_args->out, "--out", {drive_args->scenario, drive_args->config});
    const sim::Scenario scenario = sim::LoadScenario(drive_args->scenario);
    sim::DriveOptions options = LoadDriveOptions(drive_args->config);
    options.seed = drive_args->seed;
    io::OutputDirectory out(drive_args->out, drive_args->overwrite, "recording", "frames.csv");
    StopCleanlyOnInterrupt();
    const sim::DriveSummary summary = DriveToDirectory(scenario, options, out.path());
    out.Commit();
    spdlog::info("{}: {} frames, {:.1f} s, {:.2f} m driven: {}", scenario.name, summary.frames,
                 summary.duration_s, summary.distance_m, summary.status);
    if (!summary.completed) throw RunFailed("drive did not complete: " + summary.status);
  });
}

}  // namespace mapless::app
