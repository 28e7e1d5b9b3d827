#include "mapless/run/generated_suite.h"

#include <atomic>
#include <filesystem>
#include <map>
#include <mutex>
#include <thread>

#include "mapless/core/check.h"
#include "mapless/eval/generated.h"
#include "mapless/io/atomic_file.h"
#include "mapless/run/report.h"
#include "mapless/run/text.h"
#include "mapless/sim/generator.h"

namespace mapless::run {

namespace {

struct World {
  std::string text;  // the scenario's YAML
  std::string file;  // where it came from ("" : generated)
  std::uint64_t seed = 1;
  sim::Scenario scenario;
};

// World k: generated from seed + k, or the k-th file given.
World MakeWorld(const GeneratedSuiteOptions& o, std::size_t k) {
  World w;
  if (!o.world_files.empty()) {
    w.file = o.world_files[k];
    w.seed = o.seed;
    w.scenario = sim::LoadScenario(w.file);
    return w;
  }
  sim::GenerateOptions g;
  g.seed = o.seed + k;
  g.kind = o.kind;
  w.seed = g.seed;
  w.text = sim::GenerateScenarioYaml(g);
  w.scenario = sim::ParseScenario(w.text, "generated world " + std::to_string(g.seed), "");
  return w;
}

// Runs fn(0) ... fn(n - 1) on `jobs` threads, each taking the next world when it is done.
void RunOnThreads(std::size_t n, int jobs, const std::function<void(std::size_t)>& fn) {
  std::atomic<std::size_t> next{0};
  std::vector<std::thread> threads;
  std::exception_ptr error;
  std::mutex error_mutex;
  for (int j = 0; j < std::max(1, jobs); ++j) {
    threads.emplace_back([&] {
      for (std::size_t k = next++; k < n; k = next++) {
        try {
          fn(k);
        } catch (...) {
          const std::lock_guard<std::mutex> lock(error_mutex);
          if (!error) error = std::current_exception();
          next = n;
        }
      }
    });
  }
  for (std::thread& t : threads) t.join();
  if (error) std::rethrow_exception(error);
}

std::string Outcome(const eval::GeneratedWorldResult& r) {
  if (r.collided) return "collision";
  if (r.success)
    return r.obstacle && r.stopped_at_obstacle && !r.arrived ? "stopped at obstacle" : "success";
  if (r.no_answer) return "no answer";
  return "failed";
}

nlohmann::json WorldJson(const eval::GeneratedWorldResult& r, std::uint64_t seed,
                         const std::string& replay) {
  nlohmann::json stops = nlohmann::json::array();
  for (const eval::GeneratedStop& s : r.stops)
    stops.push_back({{"start_s", s.start_s},
                     {"duration_s", s.duration_s},
                     {"reason", s.reason},
                     {"at_obstacle", s.at_obstacle}});
  nlohmann::json j = {{"world", r.world},
                      {"seed", seed},
                      {"kind", r.kind},
                      {"feasible", r.feasible},
                      {"obstacle_on_path", r.obstacle},
                      {"outcome", Outcome(r)},
                      {"success", r.success},
                      {"arrived", r.arrived},
                      {"collided", r.collided},
                      {"stopped_at_obstacle", r.stopped_at_obstacle},
                      {"no_answer", r.no_answer},
                      {"end_reason", r.end_reason},
                      {"final_error_m", r.final_error_m},
                      {"duration_s", r.duration_s},
                      {"false_stops", r.false_stops()},
                      {"longest_false_stop_s", r.longest_false_stop_s()},
                      {"stops", stops}};
  if (!replay.empty()) j["replay"] = replay;
  return j;
}

// The summary lines and their JSON.
void Summarise(const std::vector<eval::GeneratedWorldResult>& results, nlohmann::json* j,
               std::string* table) {
  int feasible = 0, feasible_ok = 0, infeasible_ok = 0, collisions = 0, no_answer = 0;
  int false_stops = 0, false_over_5 = 0, obstacle_worlds = 0, stopped_before = 0;
  double longest = 0.0;
  std::map<std::string, int> stop_kinds, end_kinds;
  for (const auto& r : results) {
    feasible += r.feasible ? 1 : 0;
    feasible_ok += r.feasible && r.success ? 1 : 0;
    infeasible_ok += !r.feasible && r.success ? 1 : 0;
    collisions += r.collided ? 1 : 0;
    no_answer += r.no_answer ? 1 : 0;
    obstacle_worlds += r.obstacle ? 1 : 0;
    stopped_before += r.obstacle && r.stopped_at_obstacle ? 1 : 0;
    for (const eval::GeneratedStop& s : r.stops) {
      ++stop_kinds[(s.at_obstacle ? "[obstacle] " : "[false] ") + eval::StopKind(s.reason)];
      if (s.at_obstacle) continue;
      ++false_stops;
      false_over_5 += s.duration_s > 5.0 ? 1 : 0;
      longest = std::max(longest, s.duration_s);
    }
    ++end_kinds[eval::StopKind(r.end_reason.substr(0, 160))];
  }
  const int n = static_cast<int>(results.size());
  (*j)["worlds"] = n;
  (*j)["feasible"] = feasible;
  (*j)["successes_feasible"] = feasible_ok;
  (*j)["success_rate_feasible"] = feasible > 0 ? static_cast<double>(feasible_ok) / feasible : 0.0;
  (*j)["successes_infeasible"] = infeasible_ok;
  (*j)["collisions"] = collisions;
  (*j)["false_stops"] = false_stops;
  (*j)["false_stops_over_5s"] = false_over_5;
  (*j)["longest_false_stop_s"] = longest;
  (*j)["obstacle_worlds"] = obstacle_worlds;
  (*j)["stopped_before_obstacle"] = stopped_before;
  (*j)["no_answer"] = no_answer;
  (*j)["stop_reasons"] = stop_kinds;
  (*j)["end_reasons"] = end_kinds;
  Appendf(table, "successes on feasible worlds: %d/%d (%.3f); on infeasible: %d/%d\n", feasible_ok,
          feasible, feasible > 0 ? static_cast<double>(feasible_ok) / feasible : 0.0, infeasible_ok,
          n - feasible);
  Appendf(table, "collisions: %d; runs that ended without an answer: %d\n", collisions, no_answer);
  Appendf(table, "false stops: %d (longer than 5 s: %d; longest %.1f s)\n", false_stops,
          false_over_5, longest);
  Appendf(table, "worlds with an object on the path: %d, stopped before it in %d\n",
          obstacle_worlds, stopped_before);
  table->append(
      "stop reasons ([false]: nothing new near the path; [obstacle]: the added object "
      "within 1.5 m):\n");
  for (const auto& [kind, count] : stop_kinds)
    Appendf(table, "  %4d  %s\n", count, kind.substr(0, 150).c_str());
  table->append("how the runs ended:\n");
  for (const auto& [kind, count] : end_kinds)
    Appendf(table, "  %4d  %s\n", count, kind.substr(0, 150).c_str());
}

}  // namespace

SuiteOutput RunGeneratedSuite(const GeneratedSuiteOptions& options) {
  eval::GeneratedRunOptions run_options;
  run_options.method = options.method;
  run_options.max_blocked_s = options.max_blocked_s;
  run_options.watch = options.watch;
  run_options.Validate();
  MAPLESS_CHECK(options.worlds >= 1 || !options.world_files.empty(),
                "GeneratedSuiteOptions.worlds = " << options.worlds << "; must be >= 1");
  if (!options.report_dir.empty()) io::MakeDirectories(options.report_dir + "/worlds");
  const std::size_t n = options.world_files.empty() ? static_cast<std::size_t>(options.worlds)
                                                    : options.world_files.size();
  std::vector<eval::GeneratedWorldResult> results(n);
  std::vector<std::uint64_t> seeds(n);
  std::vector<std::string> replays(n), files(n);
  if (options.on_start) options.on_start(static_cast<int>(n));
  RunOnThreads(n, options.jobs, [&](std::size_t k) {
    const World w = MakeWorld(options, k);
    eval::GeneratedRunOptions o = run_options;
    o.seed = w.seed;
    seeds[k] = w.seed;
    results[k] = eval::RunGeneratedWorld(w.scenario, o);
    const auto& r = results[k];
    // Every world into the report (its pictures load it); a failure's also where it is replayed.
    files[k] = w.file;
    if (!w.text.empty() && !options.report_dir.empty()) {
      files[k] = options.report_dir + "/worlds/" + r.world + ".yaml";
      io::WriteFileAtomic(files[k], w.text, false);
    }
    const bool failure = !r.success || r.collided || r.no_answer || r.longest_false_stop_s() > 5.0;
    if (failure && !w.text.empty() && !options.failures_dir.empty()) {
      const std::string file = options.failures_dir + "/" + r.world + ".yaml";
      io::MakeDirectories(options.failures_dir);
      io::WriteFileAtomic(file, w.text, false);
      if (files[k].empty()) files[k] = file;
    }
    if (failure && !files[k].empty())
      replays[k] = "mapless eval generated --method " + options.method + " --world " + files[k] +
                   " --seed " + std::to_string(w.seed);
    if (options.on_entry_done)
      options.on_entry_done(r.world + ": " + Outcome(r) + " (" + r.end_reason.substr(0, 100) + ")");
  });
  nlohmann::json j = {{"suite", "generated"},
                      {"method", options.method},
                      {"seed", options.seed},
                      {"kind", options.kind},
                      {"max_blocked_s", options.max_blocked_s},
                      {"on_obstacle", options.watch ? "stop" : "off"},
                      {"results", nlohmann::json::array()}};
  std::string table;
  Appendf(&table, "%-22s %-9s %-4s %-4s %-19s %5s %6s %7s  %s\n", "world", "kind", "feas", "obst",
          "outcome", "stops", "false", "longest", "how it ended");
  for (std::size_t k = 0; k < n; ++k) {
    const auto& r = results[k];
    j["results"].push_back(WorldJson(r, seeds[k], replays[k]));
    Appendf(&table, "%-22s %-9s %-4s %-4s %-19s %5zu %6d %6.1fs  %s\n", r.world.c_str(),
            r.kind.c_str(), r.feasible ? "yes" : "no", r.obstacle ? "yes" : "no",
            Outcome(r).c_str(), r.stops.size(), r.false_stops(), r.longest_false_stop_s(),
            r.end_reason.substr(0, 90).c_str());
  }
  Summarise(results, &j, &table);
  for (std::size_t k = 0; k < n; ++k)
    if (!replays[k].empty()) Appendf(&table, "replay: %s\n", replays[k].c_str());
  if (!options.report_dir.empty()) {
    std::vector<eval::EntryResult> entries(n);
    std::vector<const eval::EntryResult*> pointers;
    std::vector<std::string> experiments;
    for (std::size_t k = 0; k < n; ++k) {
      const auto& r = results[k];
      eval::EntryResult& e = entries[k];
      e.scenario = files[k];
      e.controller = options.method;
      e.runs = 1;
      e.successes = r.success ? 1 : 0;
      e.collisions = r.collided ? 1 : 0;
      e.final_error_m_rms = r.final_error_m;
      e.reference_path = r.reference_path;
      e.paths = {r.path};
      if (!r.success) e.failures = {r.end_reason};
      if (files[k].empty()) continue;
      pointers.push_back(&e);
      experiments.push_back(Outcome(r));
    }
    WriteSuiteReport(options.report_dir, "generated " + options.method, 1, options.seed, pointers,
                     experiments, std::vector<const RunTrace*>(pointers.size(), nullptr));
  }
  return {j, table};
}

}  // namespace mapless::run
