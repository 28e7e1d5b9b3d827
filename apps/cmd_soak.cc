// `mapless soak`: the long-run check of issue 6. Teaches a route, repeats it lap after lap for a
// simulated hour (fast-forwarded), and checks that memory stays flat (peak RSS at the end within
// --max-rss-growth of the peak after the first lap) and that the cost per frame does not drift
// (median of the last three laps within --max-cost-drift of the first three). Exit 1 when either
// fails. Memory is read from /proc/self/status (Linux).
#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "cli_common.h"
#include "mapless/core/check.h"
#include "mapless/eval/soak.h"

namespace mapless::app {
namespace {

// VmRSS and VmHWM (peak) of this process, in MiB; 0 when /proc is not there.
std::pair<double, double> ResidentMiB() {
  std::ifstream status("/proc/self/status");
  std::string line;
  double rss = 0.0;
  double peak = 0.0;
  while (std::getline(status, line)) {
    const auto value = [&](const char* key) {
      return std::stod(line.substr(std::string(key).size())) / 1024.0;  // kB
    };
    if (line.rfind("VmRSS:", 0) == 0) rss = value("VmRSS:");
    if (line.rfind("VmHWM:", 0) == 0) peak = value("VmHWM:");
  }
  return {rss, peak};
}

double Median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

}  // namespace

void AddSoakCommand(CLI::App* app) {
  struct Args {
    double minutes = 60.0;
    std::string scenario = "table1_almost_straight";
    std::uint64_t seed = 1;
    double max_rss_growth = 0.10;
    double max_cost_drift = 0.20;
    bool json = false;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app->add_subcommand(
      "soak", "Repeat a taught route lap after lap for a simulated hour; check memory and cost");
  cmd->add_option("--minutes", args->minutes, "Simulated minutes of repeating")
      ->capture_default_str()
      ->check(FiniteIn(0.1, 24.0 * 60.0));
  cmd->add_option("--scenario", args->scenario, "Built-in scenario or YAML file")
      ->capture_default_str();
  cmd->add_option("--seed", args->seed, "Seed of the noise and the start offsets")
      ->capture_default_str()
      ->check(SeedCheck());
  cmd->add_option("--max-rss-growth", args->max_rss_growth,
                  "Allowed growth of peak RSS from the end of lap 1 to the end (fraction)")
      ->capture_default_str()
      ->check(FiniteIn(0.0, 10.0));
  cmd->add_option("--max-cost-drift", args->max_cost_drift,
                  "Allowed growth of the median frame cost, last 3 laps over first 3 (fraction; "
                  "0 turns the check off, e.g. on a loaded machine)")
      ->capture_default_str()
      ->check(FiniteIn(0.0, 10.0));
  cmd->add_flag("--json", args->json, "Print one JSON object at the end (laps go to stderr)");
  cmd->callback([args] {
    eval::SoakOptions options;
    options.scenario = args->scenario;
    options.duration_s = args->minutes * 60.0;
    options.repeat.seed = args->seed;
    FILE* table = args->json ? stderr : stdout;
    nlohmann::json j;
    j["scenario"] = args->scenario;
    j["minutes"] = args->minutes;
    j["seed"] = args->seed;
    j["laps"] = nlohmann::json::array();
    std::vector<double> lap_medians;
    double peak_after_first = 0.0;
    double peak_end = 0.0;
    std::fprintf(table, "%4s %8s %6s %-9s %8s %10s %9s %9s %9s\n", "lap", "sim s", "frames",
                 "result", "final", "frame med", "frame p95", "RSS MiB", "peak MiB");
    const eval::SoakSummary summary = eval::RunSoak(
        options,
        [&](const eval::SoakLap& lap) {
          const auto [rss, peak] = ResidentMiB();
          if (lap.lap == 1) peak_after_first = peak;
          peak_end = peak;
          lap_medians.push_back(lap.median_frame_ms);
          const char* result = lap.completed ? "completed" : lap.collided ? "collided" : "timeout";
          std::fprintf(table, "%4d %8.0f %6d %-9s %7.2fm %8.2fms %7.2fms %9.1f %9.1f\n", lap.lap,
                       lap.end_time_s, lap.frames, result, lap.final_error_m, lap.median_frame_ms,
                       lap.p95_frame_ms, rss, peak);
          std::fflush(table);
          j["laps"].push_back({{"lap", lap.lap},
                               {"end_time_s", lap.end_time_s},
                               {"frames", lap.frames},
                               {"completed", lap.completed},
                               {"collided", lap.collided},
                               {"final_error_m", lap.final_error_m},
                               {"median_frame_ms", lap.median_frame_ms},
                               {"p95_frame_ms", lap.p95_frame_ms},
                               {"rss_mib", rss},
                               {"peak_rss_mib", peak}});
        },
        [] {
          return std::chrono::duration<double, std::milli>(
                     std::chrono::steady_clock::now().time_since_epoch())
              .count();
        });
    const std::size_t k = std::min<std::size_t>(3, lap_medians.size());
    const double early =
        Median({lap_medians.begin(), lap_medians.begin() + static_cast<std::ptrdiff_t>(k)});
    const double late =
        Median({lap_medians.end() - static_cast<std::ptrdiff_t>(k), lap_medians.end()});
    const double rss_growth = peak_after_first > 0.0 ? peak_end / peak_after_first - 1.0 : 0.0;
    const double cost_drift = early > 0.0 ? late / early - 1.0 : 0.0;
    const bool rss_ok = rss_growth <= args->max_rss_growth;
    const bool cost_ok = args->max_cost_drift <= 0.0 || cost_drift <= args->max_cost_drift;
    std::fprintf(
        table,
        "soak: %d laps (%d completed), %d frames, %.0f simulated s; peak RSS %.1f MiB "
        "after lap 1, %.1f MiB at the end (%+.1f%%, limit %+.0f%%); median frame cost "
        "%.2f ms (first 3 laps) -> %.2f ms (last 3) (%+.1f%%%s)\n",
        summary.laps, summary.completed_laps, summary.frames, summary.simulated_s, peak_after_first,
        peak_end, 100.0 * rss_growth, 100.0 * args->max_rss_growth, early, late, 100.0 * cost_drift,
        args->max_cost_drift > 0.0
            ? (", limit +" + std::to_string(static_cast<int>(100.0 * args->max_cost_drift)) + "%")
                  .c_str()
            : ", not checked");
    j["summary"] = {{"laps", summary.laps},
                    {"completed_laps", summary.completed_laps},
                    {"frames", summary.frames},
                    {"simulated_s", summary.simulated_s},
                    {"peak_rss_after_first_lap_mib", peak_after_first},
                    {"peak_rss_end_mib", peak_end},
                    {"rss_growth", rss_growth},
                    {"median_frame_ms_first_laps", early},
                    {"median_frame_ms_last_laps", late},
                    {"cost_drift", cost_drift},
                    {"rss_ok", rss_ok},
                    {"cost_ok", cost_ok}};
    if (args->json) std::cout << j.dump() << "\n";
    if (!rss_ok) throw RunFailed("soak: peak RSS grew " + std::to_string(100.0 * rss_growth) + "%");
    if (!cost_ok)
      throw RunFailed("soak: the median frame cost drifted " + std::to_string(100.0 * cost_drift) +
                      "%");
  });
}

}  // namespace mapless::app
