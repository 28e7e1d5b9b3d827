// `mapless eval SUITE`: reproduce a paper's experiments on the simulator; one JSON object
// {"suite", "results": [{"scenario", "controller", "runs", "successes", "final_error_m_rms",
// "final_error_m_std", "final_error_m_max", "lateral_rms_m", "collisions", ...}]} and a readable
// table.
#include <spdlog/spdlog.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <future>
#include <iostream>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>

#include "cli_common.h"
#include "fleet.h"
#include "mapless/core/check.h"
#include "mapless/eval/eigenspace.h"
#include "mapless/eval/potential.h"
#include "mapless/eval/suite.h"
#include "progress.h"
#include "run_report.h"
#include "run_traces.h"

namespace mapless::app {

namespace {

// Calls fn(0) ... fn(n - 1), `jobs` at a time (each entry is independent and seeded, so the
// results do not depend on `jobs`).
// Progress (runs done, time left) shows on a terminal.
void RunInBatches(std::size_t n, int jobs, const std::function<void(std::size_t)>& fn) {
  Progress progress("eval", static_cast<int>(n));
  const auto run = [&](std::size_t k) {
    fn(k);
    progress.Done();
  };
  std::size_t next = 0;
  while (next < n) {
    std::vector<std::future<void>> batch;
    for (int j = 0; j < jobs && next < n; ++j, ++next)
      batch.push_back(std::async(std::launch::async, run, next));
    for (auto& f : batch) f.get();
  }
}

template <typename Trace>
std::vector<const RunTrace*> TracePointers(const std::vector<std::unique_ptr<Trace>>& traces) {
  std::vector<const RunTrace*> out;
  for (const auto& t : traces) out.push_back(t.get());
  return out;
}

nlohmann::json SuiteJson(const std::string& suite, int runs, std::uint64_t seed) {
  nlohmann::json j;
  j["suite"] = suite;
  j["runs"] = runs;
  j["seed"] = seed;
  j["results"] = nlohmann::json::array();
  return j;
}

nlohmann::json EntryJson(const eval::EntryResult& r) {
  return {{"scenario", r.scenario},
          {"controller", r.controller},
          {"runs", r.runs},
          {"successes", r.successes},
          {"final_error_m_rms", r.final_error_m_rms},
          {"final_error_m_std", r.final_error_m_std},
          {"final_error_m_max", r.final_error_m_max},
          {"lateral_rms_m", r.lateral_rms_m},
          {"collisions", r.collisions},
          {"obstacle_stops", r.obstacle_stops},
          {"went_round", r.went_round},
          {"stops_at_added_object", r.stops_at_added_object},
          {"min_clearance_m",
           std::isfinite(r.min_clearance_m) ? nlohmann::json(r.min_clearance_m) : nlohmann::json()},
          {"failures", r.failures}};
}

// `mapless eval potential`: Ohnishi & Imiya, Section 5 (see eval/potential.h).
void RunPotentialSuite(int runs, std::uint64_t seed, bool json_out, int jobs,
                       const std::string& only, const std::string& report_dir) {
  std::vector<eval::PotentialEntry> entries;
  for (const auto& e : eval::PotentialSuiteEntries())
    if (only.empty() || e.scenario == only) entries.push_back(e);
  if (entries.empty()) throw InputError("--only '" + only + "': not a scenario of suite potential");
  const navigation::PotentialNavOptions nav;
  std::vector<eval::PotentialEntryResult> results(entries.size());
  // With --report, the first run of each entry frame by frame.
  std::vector<std::unique_ptr<PotentialTrace>> traces(entries.size());
  RunInBatches(entries.size(), jobs, [&](std::size_t k) {
    eval::PotentialObserver observer;
    if (!report_dir.empty()) {
      traces[k] = std::make_unique<PotentialTrace>(
          1.0 / sim::LoadScenario(entries[k].scenario).camera.rate_hz);
      observer = traces[k]->Observer();
    }
    results[k] = eval::RunPotentialEntry(entries[k], runs, seed, nav, observer);
    spdlog::info("eval: {} {}: {}/{} successes", entries[k].scenario, entries[k].experiment,
                 results[k].successes, results[k].runs);
  });
  std::vector<eval::InclusionResult> inclusion;
  for (const char* name : {"corridor_straight_3p5m", "obstacle_field"})
    if (only.empty() || only == name)
      // Table 1 is about the paper's detector: its options (1 px, the whole image), not the
      // navigator's.
      inclusion.push_back(
          eval::InclusionOnSimulator(sim::LoadScenario(name), ground::DominantPlaneOptions{}));

  nlohmann::json j = SuiteJson("potential", runs, seed);
  FILE* table = json_out ? stderr : stdout;
  std::fprintf(table, "%-24s %-14s %9s %5s %10s %10s %10s\n", "scenario", "experiment", "success",
               "coll", "final rms", "dev std", "dev max");
  for (const auto& r : results) {
    nlohmann::json e = EntryJson(r);
    e["experiment"] = r.experiment;
    e["deviation_std_m"] = r.deviation_std_m;
    e["deviation_std_m_max"] = r.deviation_std_m_max;
    e["deviations_m"] = r.deviations_m;
    j["results"].push_back(e);
    std::fprintf(table, "%-24s %-14s %4d/%-4d %5d %9.3fm %9.4fm %9.4fm\n", r.scenario.c_str(),
                 r.experiment.c_str(), r.successes, r.runs, r.collisions, r.final_error_m_rms,
                 r.deviation_std_m, r.deviation_std_m_max);
  }
  j["inclusion"] = nlohmann::json::array();
  for (const auto& in : inclusion) {
    j["inclusion"].push_back({{"scenario", in.scenario},
                              {"pairs", in.pairs},
                              {"frames", in.frames},
                              {"p_d0_in_d1", in.inclusion[0]},
                              {"p_d1_in_d2", in.inclusion[1]},
                              {"p_d2_in_d3", in.inclusion[2]}});
    std::fprintf(table,
                 "inclusion %-24s %3d/%-3d pairs  P(D0<D1) %.3f  P(D1<D2) %.3f  P(D2<D3) %.3f\n",
                 in.scenario.c_str(), in.frames, in.pairs, in.inclusion[0], in.inclusion[1],
                 in.inclusion[2]);
  }
  if (json_out) std::cout << j.dump() << "\n";
  if (!report_dir.empty()) {
    std::vector<const eval::EntryResult*> entries_out;
    std::vector<std::string> experiments;
    for (const auto& r : results) entries_out.push_back(&r), experiments.push_back(r.experiment);
    WriteSuiteReport(report_dir, "potential", runs, seed, entries_out, experiments,
                     TracePointers(traces));
    spdlog::info("eval: report in {}/index.html", report_dir);
  }
}

// `mapless eval eigenspace`: Payá et al., Section 5 (see eval/eigenspace.h).
void RunEigenspaceSuite(int runs, std::uint64_t seed, bool json_out, int jobs,
                        const std::string& only, const std::string& report_dir) {
  std::vector<eval::EigenspaceEntry> entries;
  for (const auto& e : eval::EigenspaceSuiteEntries())
    if (only.empty() || e.scenario == only) entries.push_back(e);
  if (entries.empty())
    throw InputError("--only '" + only + "': not a scenario of suite eigenspace");
  std::vector<eval::EigenspaceEntryResult> results(entries.size());
  std::vector<std::unique_ptr<EigenspaceTrace>> traces(entries.size());
  RunInBatches(entries.size(), jobs, [&](std::size_t k) {
    eval::EigenspaceObserver observer;
    if (!report_dir.empty()) {
      traces[k] = std::make_unique<EigenspaceTrace>(
          1.0 / sim::LoadScenario(entries[k].scenario).camera.rate_hz);
      observer = traces[k]->Observer();
    }
    results[k] = eval::RunEigenspaceEntry(entries[k], runs, seed, observer);
    spdlog::info("eval: {} {}: {}/{} successes", entries[k].scenario, entries[k].experiment,
                 results[k].successes, results[k].runs);
  });
  nlohmann::json j = SuiteJson("eigenspace", runs, seed);
  FILE* table = json_out ? stderr : stdout;
  std::fprintf(table, "%-19s %-16s %9s %5s %10s %11s %11s %9s %9s %6s %7s %9s\n", "scenario",
               "experiment", "success", "coll", "final rms", "lateral rms", "lateral max",
               "loc +-1", "nn +-1", "stops", "at obj", "clearance");
  for (const auto& r : results) {
    nlohmann::json e = EntryJson(r);
    e["experiment"] = r.experiment;
    e["lateral_rms_m_max"] = r.lateral_rms_m_max;
    e["localization_within_one"] = r.localization_within_one;
    e["nearest_within_one"] = r.nearest_within_one;
    e["stop_frames"] = r.stops;
    j["results"].push_back(e);
    const std::string clearance =
        std::isfinite(r.min_clearance_m) ? Fixed(r.min_clearance_m, 2) + "m" : "-";
    std::fprintf(table, "%-19s %-16s %4d/%-4d %5d %9.3fm %10.3fm %10.3fm %9.3f %9.3f %6d %7d %9s\n",
                 r.scenario.c_str(), r.experiment.c_str(), r.successes, r.runs, r.collisions,
                 r.final_error_m_rms, r.lateral_rms_m, r.lateral_rms_m_max,
                 r.localization_within_one, r.nearest_within_one, r.obstacle_stops,
                 r.stops_at_added_object, clearance.c_str());
  }
  if (json_out) std::cout << j.dump() << "\n";
  if (!report_dir.empty()) {
    std::vector<const eval::EntryResult*> entries_out;
    std::vector<std::string> experiments;
    for (const auto& r : results) entries_out.push_back(&r), experiments.push_back(r.experiment);
    WriteSuiteReport(report_dir, "eigenspace", runs, seed, entries_out, experiments,
                     TracePointers(traces));
    spdlog::info("eval: report in {}/index.html", report_dir);
  }
}

}  // namespace

void AddEvalCommand(CLI::App* app) {
  struct Args {
    std::string suite;
    int runs = 10;
    std::uint64_t seed = 1;
    bool json = false;
    int jobs = 1;
    std::string only;
    std::string switching = "stdratio";
    std::string end = "scale";
    int redetect_every = navigation::RepeatOptions{}.redetect_every_frames;
    int recover_keyframes = navigation::RepeatOptions{}.recovery_keyframes;
    double carry_on_m = navigation::RepeatOptions{}.carry_on.max_distance_m;
    std::string on_obstacle;  // default: stop
    std::string report;
  };
  auto args = std::make_shared<Args>();
  auto fleet = std::make_shared<FleetEvalArgs>();
  CLI::App* cmd = app->add_subcommand(
      "eval",
      "Run an evaluation suite on the simulator (table1, funnel-scenarios, obstacles, potential, "
      "eigenspace, fleet)");
  cmd->add_option("SUITE", args->suite,
                  "table1, funnel-scenarios, obstacles, potential, eigenspace or fleet (a leader "
                  "and followers as processes)")
      ->required();
  AddFleetEvalOptions(cmd, fleet.get());
  cmd->add_option("--runs", args->runs, "Repeats per scenario and controller")
      ->capture_default_str()
      ->check(CLI::Range(1, 1000));
  cmd->add_option("--seed", args->seed, "First seed; run i uses seed + i")
      ->capture_default_str()
      ->check(SeedCheck());
  cmd->add_flag("--json", args->json, "Print one JSON object (the table goes to stderr)");
  cmd->add_option("--jobs", args->jobs, "Scenarios evaluated in parallel")
      ->capture_default_str()
      ->check(CLI::Range(1, 64));
  cmd->add_option("--only", args->only, "Evaluate only this scenario of the suite");
  cmd->add_option("--switching", args->switching,
                  "table1, funnel-scenarios: keyframe switching, stdratio, mse or scale")
      ->capture_default_str();
  cmd->add_option("--end", args->end,
                  "table1, funnel-scenarios: the last keyframe by scale, or by the switching rule "
                  "(switching)")
      ->capture_default_str();
  cmd->add_option("--redetect-every", args->redetect_every,
                  "table1, funnel-scenarios: detect and match afresh every N frames, KLT in "
                  "between (0: Algorithm 1's)")
      ->capture_default_str()
      ->check(CLI::Range(0, 1000));
  cmd->add_option("--recover-keyframes", args->recover_keyframes,
                  "table1, funnel-scenarios: keyframe recovery, up to N following keyframes (0: "
                  "off)")
      ->capture_default_str()
      ->check(CLI::Range(0, 20));
  cmd->add_option("--carry-on-m", args->carry_on_m,
                  "table1, funnel-scenarios, obstacles: carrying on along the taught odometry, "
                  "at most this many metres (0: off)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 100.0));
  cmd->add_option("--on-obstacle", args->on_obstacle,
                  "table1, funnel-scenarios, obstacles: the obstacle watch, stop (default, as in "
                  "`repeat`), avoid (go round it; the objects added at repeat time then stay for "
                  "the whole run) or off (the paper's repeat)")
      ->check(CLI::IsMember({"stop", "avoid", "off"}));
  cmd->add_option("--report", args->report,
                  "Write an HTML report (index.html: the results, each scenario from above with "
                  "every run, the error along the path; the first run's commands over time, its "
                  "method's plots and chosen frames) and PNG plots into this directory");
  cmd->callback([args, fleet] {
    if (args->suite == "fleet" && !args->report.empty())
      throw InputError(
          "--report: not for the fleet suite (its runs are processes; --keep "
          "keeps their routes and logs)");
    if (!args->report.empty()) {
      RefuseOutputOverInputs(args->report, "--report", {});
      CheckReportDir(args->report, "--report");
    }
    if (args->suite == "fleet") {
      FleetEvalArgs f = *fleet;
      f.seed = args->seed;
      RunFleetEval(f, args->json);
      return;
    }
    const bool teach_repeat = args->suite != "potential" && args->suite != "eigenspace";
    const navigation::RepeatOptions defaults;
    if (!teach_repeat &&
        (args->switching != "stdratio" || args->end != "scale" ||
         args->redetect_every != defaults.redetect_every_frames ||
         args->recover_keyframes != defaults.recovery_keyframes ||
         args->carry_on_m != defaults.carry_on.max_distance_m || !args->on_obstacle.empty()))
      throw InputError(
          "--switching, --end, --redetect-every, --recover-keyframes, --carry-on-m and "
          "--on-obstacle apply to table1, funnel-scenarios and obstacles, not " +
          args->suite);
    eval::RepeatRunOptions base;
    base.repeat.switching = navigation::ParseSwitching(args->switching);
    base.repeat.end_by_local_scale = ParseEndByLocalScale(args->end);
    base.repeat.redetect_every_frames = args->redetect_every;
    base.repeat.recovery_keyframes = args->recover_keyframes;
    base.repeat.carry_on.max_distance_m = args->carry_on_m;
    if (args->on_obstacle.empty()) args->on_obstacle = "stop";
    base.repeat.obstacle.enabled = args->on_obstacle != "off";
    base.repeat.obstacle.avoid = args->on_obstacle == "avoid";
    if (args->suite == "potential") {
      RunPotentialSuite(args->runs, args->seed, args->json, args->jobs, args->only, args->report);
      return;
    }
    if (args->suite == "eigenspace") {
      RunEigenspaceSuite(args->runs, args->seed, args->json, args->jobs, args->only, args->report);
      return;
    }
    std::vector<eval::SuiteEntry> entries = eval::SuiteEntries(args->suite);
    if (!args->only.empty()) {
      std::vector<eval::SuiteEntry> kept;
      for (const auto& e : entries) {
        if (e.scenario == args->only) kept.push_back(e);
      }
      if (kept.empty())
        throw InputError("--only '" + args->only + "': not a scenario of suite " + args->suite);
      entries = kept;
    }
    // Teach each scenario once; evaluate entries in parallel (each run is independent and seeded,
    // so the results do not depend on --jobs).
    std::map<std::string, std::pair<sim::Scenario, eval::TaughtRoute>> taught;
    for (const auto& e : entries) {
      if (taught.count(e.scenario)) continue;
      sim::Scenario s = sim::LoadScenario(e.scenario);
      // Going round: the obstacle is not taken away, so a completed route went round it.
      if (base.repeat.obstacle.avoid) s.repeat_variant = eval::ObjectsStay(s.repeat_variant);
      spdlog::info("eval: teaching {}", e.scenario);
      taught.emplace(e.scenario,
                     std::make_pair(s, eval::TeachOnSimulator(s, navigation::TeachOptions{})));
    }
    std::vector<eval::EntryResult> results(entries.size());
    std::vector<std::unique_ptr<RepeatTrace>> traces(entries.size());
    RunInBatches(entries.size(), args->jobs, [&](std::size_t k) {
      const auto& [scenario, route] = taught.at(entries[k].scenario);
      eval::RepeatObserver observer;
      if (!args->report.empty()) {
        traces[k] = std::make_unique<RepeatTrace>(route, 1.0 / scenario.camera.rate_hz);
        observer = traces[k]->Observer();
      }
      results[k] = eval::RunEntry(scenario, route, entries[k].controller, args->runs, args->seed,
                                  base, observer);
      spdlog::info("eval: {} {}: {}/{} successes", entries[k].scenario, results[k].controller,
                   results[k].successes, results[k].runs);
    });
    nlohmann::json j = SuiteJson(args->suite, args->runs, args->seed);
    j["switching"] = args->switching;
    j["redetect_every"] = args->redetect_every;
    j["recover_keyframes"] = args->recover_keyframes;
    j["on_obstacle"] = args->on_obstacle;
    j["end"] = args->end;
    FILE* table = args->json ? stderr : stdout;
    std::fprintf(table, "%-30s %-9s %9s %10s %10s %10s %10s %5s %6s %7s %9s %6s\n", "scenario",
                 "control", "success", "final rms", "final std", "final max", "lateral", "coll",
                 "stops", "at obj", "clearance", "round");
    for (const auto& r : results) {
      j["results"].push_back(EntryJson(r));
      const std::string clearance =
          std::isfinite(r.min_clearance_m) ? Fixed(r.min_clearance_m, 2) + "m" : "-";
      std::fprintf(table, "%-30s %-9s %4d/%-4d %9.2fm %9.2fm %9.2fm %9.2fm %5d %6d %7d %9s %6d\n",
                   r.scenario.c_str(), r.controller.c_str(), r.successes, r.runs,
                   r.final_error_m_rms, r.final_error_m_std, r.final_error_m_max, r.lateral_rms_m,
                   r.collisions, r.obstacle_stops, r.stops_at_added_object, clearance.c_str(),
                   r.went_round);
    }
    if (args->json) std::cout << j.dump() << "\n";
    if (!args->report.empty()) {
      std::vector<const eval::EntryResult*> entries_out;
      for (const auto& r : results) entries_out.push_back(&r);
      WriteSuiteReport(args->report, args->suite, args->runs, args->seed, entries_out,
                       std::vector<std::string>(results.size()), TracePointers(traces));
      spdlog::info("eval: report in {}/index.html", args->report);
    }
  });
}

}  // namespace mapless::app
