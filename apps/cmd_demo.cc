// `mapless demo`: the main job. On the built-in simulator: teach a route by driving it (camera
// frames, poses, the route store) and repeat it with the sloped funnel lane from a perturbed start
// with motion and image noise; follow a route with the eigenspace follower while the leader is
// still teaching it; drive the visual potential to a destination and home. Then the report:
// OUT/report/index.html with PNG plots beside it.
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
#include "mapless/run/demo.h"
#include "progress.h"

namespace mapless::app {

void AddDemoCommand(CLI::App* app) {
  struct Args {
    std::string scenario = "narrow_room_sharp_turn";
    std::string out = "demo_out";
    std::string config;
    std::uint64_t seed = 1;
    std::string eigenspace_scenario = "office_aliasing";
    std::string potential_scenario = "obstacle_field";
  };
  auto args = std::make_shared<Args>();
  CLI::App* demo = app->add_subcommand("demo",
                                       "The three methods on the built-in simulator: teach a route "
                                       "and repeat it (sloped funnel lane), follow a route the "
                                       "leader is still teaching (eigenspace), drive to a "
                                       "destination and home (visual potential); write a report");
  demo->add_option("--scenario", args->scenario, "Built-in scenario name or YAML file")
      ->capture_default_str();
  demo->add_option("--out", args->out, "Output directory")->capture_default_str();
  demo->add_option("--seed", args->seed, "Seed of motion and image noise")
      ->capture_default_str()
      ->check(SeedCheck());
  demo->add_option("--config", args->config, "Run configuration YAML (see config/default.yaml)");
  demo->add_option("--eigenspace-scenario", args->eigenspace_scenario,
                   "Scenario of the eigenspace follower (leader still teaching)")
      ->capture_default_str();
  demo->add_option("--potential-scenario", args->potential_scenario,
                   "Scenario of the visual potential (its first destination, then home)")
      ->capture_default_str();
  demo->callback([args] {
    RefuseOutputOverInputs(args->out, "--out", {args->scenario, args->config});
    const sim::Scenario scenario = sim::LoadScenario(args->scenario);
    sim::DriveOptions options = LoadDriveOptions(args->config);
    options.seed = args->seed;
    // An earlier demo's output (it has teach/frames.csv, even when that demo was killed) is
    // replaced when this demo is done; any other directory with content is refused.
    io::OutputDirectory out_dir(args->out, /*replace=*/true, "demo's output", "teach/frames.csv");
    StopCleanlyOnInterrupt();
    Progress progress("demo", 4);
    progress.Stage(1, "teaching the route");
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

    // 1. Repeat with the sloped funnel lane, decisions logged as JSON lines.
    progress.Stage(2, "repeating with the sloped funnel lane");
    std::vector<run::DemoResult> results;
    JsonLines log((out / "repeat.jsonl").string(), /*in_place=*/true);
    results.push_back(run::DemoRepeat(
        scenario, taught, args->seed, [&log](const nlohmann::json& j) { log.Write(j); },
        ThrowIfInterrupted));
    spdlog::info("demo: repeat: {}", results.back().status);
    // 2. The eigenspace follower while its leader is still teaching.
    progress.Stage(3, "eigenspace follower while the leader teaches");
    results.push_back(
        run::DemoEigenspace(args->eigenspace_scenario, args->seed, ThrowIfInterrupted));
    spdlog::info("demo: eigenspace follower: {}", results.back().status);
    // 3. The visual potential to a destination and home.
    progress.Stage(4, "visual potential to a destination and home");
    results.push_back(run::DemoPotential(args->potential_scenario, args->seed, ThrowIfInterrupted));
    spdlog::info("demo: visual potential: {}", results.back().status);

    report::HtmlReport html("mapless demo");
    html.Byline(run::ReportByline());
    html.Paragraph("The three methods of mapless on the built-in simulator, seed " +
                   std::to_string(args->seed) +
                   ". Every picture and plot is in this file; nothing is loaded from elsewhere.");
    html.Heading("Results");
    std::vector<std::vector<std::string>> rows;
    for (const run::DemoResult& r : results) rows.push_back(r.row);
    html.Table({"method", "scenario", "success", "final error (m)", "detail", "success means"},
               rows);
    std::vector<run::RunSection> sections;
    for (const run::DemoResult& r : results) {
      run::AddRunSection(&html, r.section);
      sections.push_back(r.section);
    }
    const std::string index = run::WriteReport((out / "report").string(), html, sections);
    nlohmann::json j{{"scenario", scenario.name}, {"keyframes", taught.route->keyframes.size()}};
    j["runs"] = nlohmann::json::array();
    for (const run::DemoResult& r : results)
      j["runs"].push_back({{"method", r.row[0]},
                           {"scenario", r.row[1]},
                           {"success", r.success},
                           {"status", r.status},
                           {"final_error_m", std::stod(r.row[3])}});
    io::WriteFileAtomic((out / "summary.json").string(), j.dump(2) + "\n");
    out_dir.Commit();
    spdlog::info(
        "demo: wrote {0}/teach/ (frames, poses), {0}/route/, {0}/repeat.jsonl, "
        "{0}/summary.json and the report: {0}/report/index.html (PNG plots beside it)",
        args->out);
    int failed = 0;
    for (const run::DemoResult& r : results) failed += !r.success;
    if (failed > 0)
      throw RunFailed("demo: " + std::to_string(failed) + " of the three runs did not succeed");
  });
}

}  // namespace mapless::app
