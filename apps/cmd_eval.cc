// `mapless eval SUITE`: reproduce a paper's experiments on the simulator; one JSON object
// {"suite", "results": [{"scenario", "controller", "runs", "successes", "final_error_m_rms",
// "final_error_m_std", "lateral_rms_m", "collisions"}]} and a readable table.
#include <spdlog/spdlog.h>

#include <cstdio>
#include <future>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>

#include "cli_common.h"
#include "mapless/core/check.h"
#include "mapless/eval/suite.h"

namespace mapless::app {

void AddEvalCommand(CLI::App* app) {
  struct Args {
    std::string suite;
    int runs = 10;
    std::uint64_t seed = 1;
    bool json = false;
    int jobs = 1;
    std::string only;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app->add_subcommand(
      "eval", "Run an evaluation suite on the simulator (table1, funnel-scenarios)");
  cmd->add_option("SUITE", args->suite, "table1 or funnel-scenarios")->required();
  cmd->add_option("--runs", args->runs, "Repeats per scenario and controller")
      ->capture_default_str()
      ->check(CLI::Range(1, 1000));
  cmd->add_option("--seed", args->seed, "First seed; run i uses seed + i")->capture_default_str();
  cmd->add_flag("--json", args->json, "Print one JSON object (the table goes to stderr)");
  cmd->add_option("--jobs", args->jobs, "Scenarios evaluated in parallel")
      ->capture_default_str()
      ->check(CLI::Range(1, 64));
  cmd->add_option("--only", args->only, "Evaluate only this scenario of the suite");
  cmd->callback([args] {
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
      spdlog::info("eval: teaching {}", e.scenario);
      taught.emplace(e.scenario,
                     std::make_pair(s, eval::TeachOnSimulator(s, navigation::TeachOptions{})));
    }
    std::vector<eval::EntryResult> results(entries.size());
    std::size_t next = 0;
    while (next < entries.size()) {
      std::vector<std::future<void>> batch;
      for (int j = 0; j < args->jobs && next < entries.size(); ++j, ++next) {
        const std::size_t k = next;
        batch.push_back(std::async(std::launch::async, [&, k] {
          const auto& [scenario, route] = taught.at(entries[k].scenario);
          results[k] = eval::RunEntry(scenario, route, entries[k].controller, args->runs,
                                      args->seed, eval::RepeatRunOptions{});
          spdlog::info("eval: {} {}: {}/{} successes", entries[k].scenario, results[k].controller,
                       results[k].successes, results[k].runs);
        }));
      }
      for (auto& f : batch) f.get();
    }
    nlohmann::json j;
    j["suite"] = args->suite;
    j["runs"] = args->runs;
    j["seed"] = args->seed;
    j["results"] = nlohmann::json::array();
    FILE* table = args->json ? stderr : stdout;
    std::fprintf(table, "%-30s %-9s %9s %10s %10s %10s %5s\n", "scenario", "control", "success",
                 "final rms", "final std", "lateral", "coll");
    for (const auto& r : results) {
      j["results"].push_back({{"scenario", r.scenario},
                              {"controller", r.controller},
                              {"runs", r.runs},
                              {"successes", r.successes},
                              {"final_error_m_rms", r.final_error_m_rms},
                              {"final_error_m_std", r.final_error_m_std},
                              {"lateral_rms_m", r.lateral_rms_m},
                              {"collisions", r.collisions},
                              {"failures", r.failures}});
      std::fprintf(table, "%-30s %-9s %4d/%-4d %9.2fm %9.2fm %9.2fm %5d\n", r.scenario.c_str(),
                   r.controller.c_str(), r.successes, r.runs, r.final_error_m_rms,
                   r.final_error_m_std, r.lateral_rms_m, r.collisions);
    }
    if (args->json) std::cout << j.dump() << "\n";
  });
}

}  // namespace mapless::app
