#include "mapless/run/suites.h"

#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <future>
#include <map>
#include <memory>

#include "mapless/core/check.h"
#include "mapless/eval/eigenspace.h"
#include "mapless/eval/lifelong.h"
#include "mapless/eval/potential.h"
#include "mapless/eval/suite.h"
#include "mapless/run/report.h"
#include "mapless/run/text.h"
#include "mapless/run/traces.h"
#include "mapless/sim/sessions.h"

namespace mapless::run {

namespace {

// Calls fn(0) ... fn(n - 1), `jobs` at a time (each entry is independent and seeded, so the
// results do not depend on `jobs`).
void RunInBatches(std::size_t n, const SuiteOptions& options,
                  const std::function<std::string(std::size_t)>& fn) {
  if (options.on_start) options.on_start(static_cast<int>(n));
  const auto run = [&](std::size_t k) {
    const std::string line = fn(k);
    if (options.on_entry_done) options.on_entry_done(line);
  };
  const int jobs = options.jobs;
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
          {"learned", r.learned},
          {"stops_at_added_object", r.stops_at_added_object},
          {"min_clearance_m",
           std::isfinite(r.min_clearance_m) ? nlohmann::json(r.min_clearance_m) : nlohmann::json()},
          {"failures", r.failures}};
}

}  // namespace

// `mapless eval potential`: Ohnishi & Imiya, Section 5 (see eval/potential.h).
SuiteOutput RunPotentialSuite(const SuiteOptions& options) {
  const int runs = options.runs;
  const std::uint64_t seed = options.seed;
  const std::string& only = options.only;
  const std::string& report_dir = options.report_dir;
  std::vector<eval::PotentialEntry> entries;
  for (const auto& e : eval::PotentialSuiteEntries())
    if (only.empty() || e.scenario == only) entries.push_back(e);
  if (entries.empty()) throw InputError("--only '" + only + "': not a scenario of suite potential");
  const navigation::PotentialNavOptions nav;
  std::vector<eval::PotentialEntryResult> results(entries.size());
  // With --report, the first run of each entry frame by frame.
  std::vector<std::unique_ptr<PotentialTrace>> traces(entries.size());
  RunInBatches(entries.size(), options, [&](std::size_t k) {
    eval::PotentialObserver observer;
    if (!report_dir.empty()) {
      traces[k] = std::make_unique<PotentialTrace>(
          1.0 / sim::LoadScenario(entries[k].scenario).camera.rate_hz);
      observer = traces[k]->Observer();
    }
    results[k] = eval::RunPotentialEntry(entries[k], runs, seed, nav, observer);
    return entries[k].scenario + " " + entries[k].experiment + ": " +
           std::to_string(results[k].successes) + "/" + std::to_string(results[k].runs) +
           " successes";
  });
  std::vector<eval::InclusionResult> inclusion;
  for (const char* name : {"corridor_straight_3p5m", "obstacle_field"})
    if (only.empty() || only == name)
      // Table 1 is about the paper's detector: its options (1 px, the whole image), not the
      // navigator's.
      inclusion.push_back(
          eval::InclusionOnSimulator(sim::LoadScenario(name), ground::DominantPlaneOptions{}));

  nlohmann::json j = SuiteJson("potential", runs, seed);
  std::string table;
  Appendf(&table, "%-24s %-14s %9s %5s %10s %10s %10s\n", "scenario", "experiment", "success",
          "coll", "final rms", "dev std", "dev max");
  for (const auto& r : results) {
    nlohmann::json e = EntryJson(r);
    e["experiment"] = r.experiment;
    e["deviation_std_m"] = r.deviation_std_m;
    e["deviation_std_m_max"] = r.deviation_std_m_max;
    e["deviations_m"] = r.deviations_m;
    j["results"].push_back(e);
    Appendf(&table, "%-24s %-14s %4d/%-4d %5d %9.3fm %9.4fm %9.4fm\n", r.scenario.c_str(),
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
    Appendf(&table, "inclusion %-24s %3d/%-3d pairs  P(D0<D1) %.3f  P(D1<D2) %.3f  P(D2<D3) %.3f\n",
            in.scenario.c_str(), in.frames, in.pairs, in.inclusion[0], in.inclusion[1],
            in.inclusion[2]);
  }
  if (!report_dir.empty()) {
    std::vector<const eval::EntryResult*> entries_out;
    std::vector<std::string> experiments;
    for (const auto& r : results) entries_out.push_back(&r), experiments.push_back(r.experiment);
    WriteSuiteReport(report_dir, "potential", runs, seed, entries_out, experiments,
                     TracePointers(traces));
  }
  return {j, table};
}

// `mapless eval eigenspace`: Payá et al., Section 5 (see eval/eigenspace.h).
SuiteOutput RunEigenspaceSuite(const SuiteOptions& options) {
  const int runs = options.runs;
  const std::uint64_t seed = options.seed;
  const std::string& only = options.only;
  const std::string& report_dir = options.report_dir;
  std::vector<eval::EigenspaceEntry> entries;
  for (const auto& e : eval::EigenspaceSuiteEntries())
    if (only.empty() || e.scenario == only) entries.push_back(e);
  if (entries.empty())
    throw InputError("--only '" + only + "': not a scenario of suite eigenspace");
  std::vector<eval::EigenspaceEntryResult> results(entries.size());
  std::vector<std::unique_ptr<EigenspaceTrace>> traces(entries.size());
  RunInBatches(entries.size(), options, [&](std::size_t k) {
    eval::EigenspaceObserver observer;
    if (!report_dir.empty()) {
      traces[k] = std::make_unique<EigenspaceTrace>(
          1.0 / sim::LoadScenario(entries[k].scenario).camera.rate_hz);
      observer = traces[k]->Observer();
    }
    results[k] = eval::RunEigenspaceEntry(entries[k], runs, seed, observer, options.learn);
    return entries[k].scenario + " " + entries[k].experiment + ": " +
           std::to_string(results[k].successes) + "/" + std::to_string(results[k].runs) +
           " successes";
  });
  nlohmann::json j = SuiteJson("eigenspace", runs, seed);
  j["learn"] = options.learn;
  std::string table;
  Appendf(&table, "%-19s %-16s %7s %4s %6s %7s %6s %6s %5s %6s %6s\n", "scenario", "experiment",
          "success", "coll", "final", "lateral", "loc1", "nn1", "stops", "at obj", "clear");
  for (const auto& r : results) {
    nlohmann::json e = EntryJson(r);
    e["experiment"] = r.experiment;
    e["lateral_rms_m_max"] = r.lateral_rms_m_max;
    e["localization_within_one"] = r.localization_within_one;
    e["nearest_within_one"] = r.nearest_within_one;
    e["stop_frames"] = r.stops;
    if (options.learn) e["learned"] = r.learned;
    j["results"].push_back(e);
    const std::string clearance =
        std::isfinite(r.min_clearance_m) ? Fixed(r.min_clearance_m, 2) : "-";
    Appendf(&table, "%-19s %-16s %3d/%-3d %4d %6s %7.3f %6.3f %6.3f %5d %6d %6s\n",
            r.scenario.c_str(), r.experiment.c_str(), r.successes, r.runs, r.collisions,
            r.successes > 0 ? Fixed(r.final_error_m_rms, 3).c_str() : "-", r.lateral_rms_m,
            r.localization_within_one, r.nearest_within_one, r.obstacle_stops,
            r.stops_at_added_object, clearance.c_str());
  }
  table +=
      "final: RMS distance to the route's end (m; - when no run succeeded); lateral: RMS distance "
      "to the\nleader's path (m); loc1, nn1: frames localized within one route image (Markov, "
      "nearest projection);\nstops: runs the obstacle watch stopped; at obj: ... while an added "
      "object stood there; clear:\nthe closest the robot came to it (m).\n";
  if (options.learn) {
    table +=
        "--learn: each entry's runs followed one route in turn, learning into it; views learned:";
    for (const auto& r : results) table += " " + std::to_string(r.learned);
    table += "\n";
  }
  if (!report_dir.empty()) {
    std::vector<const eval::EntryResult*> entries_out;
    std::vector<std::string> experiments;
    for (const auto& r : results) entries_out.push_back(&r), experiments.push_back(r.experiment);
    WriteSuiteReport(report_dir, "eigenspace", runs, seed, entries_out, experiments,
                     TracePointers(traces));
  }
  return {j, table};
}

// `mapless eval table1 | funnel-scenarios | obstacles`: Kassir et al., Table I and beyond.
SuiteOutput RunRepeatSuite(const std::string& suite, const SuiteOptions& options,
                           const eval::RepeatRunOptions& base, const nlohmann::json& settings) {
  std::vector<eval::SuiteEntry> entries = eval::SuiteEntries(suite);
  if (!options.only.empty()) {
    std::vector<eval::SuiteEntry> kept;
    for (const auto& e : entries)
      if (e.scenario == options.only) kept.push_back(e);
    if (kept.empty())
      throw InputError("--only '" + options.only + "': not a scenario of suite " + suite);
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
    taught.emplace(e.scenario,
                   std::make_pair(s, eval::TeachOnSimulator(s, navigation::TeachOptions{})));
  }
  std::vector<eval::EntryResult> results(entries.size());
  std::vector<std::unique_ptr<RepeatTrace>> traces(entries.size());
  RunInBatches(entries.size(), options, [&](std::size_t k) {
    const auto& [scenario, route] = taught.at(entries[k].scenario);
    eval::RepeatObserver observer;
    if (!options.report_dir.empty()) {
      traces[k] = std::make_unique<RepeatTrace>(route, 1.0 / scenario.camera.rate_hz);
      observer = traces[k]->Observer();
    }
    results[k] = eval::RunEntry(scenario, route, entries[k].controller, options.runs, options.seed,
                                base, observer);
    return entries[k].scenario + " " + results[k].controller + ": " +
           std::to_string(results[k].successes) + "/" + std::to_string(results[k].runs) +
           " successes";
  });
  nlohmann::json j = SuiteJson(suite, options.runs, options.seed);
  j.update(settings);
  std::string table;
  Appendf(&table, "%-29s %-8s %7s %6s %6s %7s %4s %5s %6s %6s %5s\n", "scenario", "control",
          "success", "final", "max", "lateral", "coll", "stops", "at obj", "clear", "round");
  for (const auto& r : results) {
    j["results"].push_back(EntryJson(r));
    const std::string clearance =
        std::isfinite(r.min_clearance_m) ? Fixed(r.min_clearance_m, 2) : "-";
    const bool any = r.successes > 0;
    Appendf(&table, "%-29s %-8s %3d/%-3d %6s %6s %7.2f %4d %5d %6d %6s %5d\n", r.scenario.c_str(),
            r.controller.c_str(), r.successes, r.runs,
            any ? Fixed(r.final_error_m_rms, 2).c_str() : "-",
            any ? Fixed(r.final_error_m_max, 2).c_str() : "-", r.lateral_rms_m, r.collisions,
            r.obstacle_stops, r.stops_at_added_object, clearance.c_str(), r.went_round);
  }
  table +=
      "final, max: RMS and largest distance to the taught end (m; - when no run succeeded); "
      "lateral: RMS\ndistance to the taught path (m); coll: runs that collided; stops: runs the "
      "obstacle watch stopped;\nat obj: ... while an added object stood there; clear: the closest "
      "the robot came to it (m); round:\nruns that went round it (--on-obstacle avoid).\n";
  if (!options.report_dir.empty()) {
    std::vector<const eval::EntryResult*> entries_out;
    for (const auto& r : results) entries_out.push_back(&r);
    WriteSuiteReport(options.report_dir, suite, options.runs, options.seed, entries_out,
                     std::vector<std::string>(results.size()), TracePointers(traces));
  }
  return {j, table};
}

SuiteOutput RunExperiencesEval(const std::string& sessions_dir,
                               const eval::ExperiencesEvalOptions& options) {
  const eval::ExperiencesFigures f =
      eval::EvalExperiences(eval::LoadSessionsDataset(sessions_dir), options);
  SuiteOutput out;
  out.json = {{"suite", "experiences"},
              {"sessions", sessions_dir},
              {"tolerance_px", f.tolerance_px},
              {"max_views", options.experiences.max_views},
              {"single_fraction", f.single_fraction},
              {"experiences_fraction", f.experiences_fraction},
              {"learned", f.learned},
              {"learned_within", f.learned_within},
              {"places", nlohmann::json::array()}};
  out.table = Format("%-6s %6s %8s %12s %8s %7s %6s\n", "place", "visits", "single", "experiences",
                     "learned", "within", "views");
  for (const auto& p : f.places) {
    out.json["places"].push_back({{"place", p.place},
                                  {"visits", p.visits},
                                  {"single_fraction", p.single_fraction()},
                                  {"experiences_fraction", p.experiences_fraction()},
                                  {"learned", p.learned},
                                  {"learned_within", p.learned_within},
                                  {"views", p.views}});
    out.table +=
        Format("%-6d %6d %8.3f %12.3f %8d %7d %6d\n", p.place, p.visits, p.single_fraction(),
               p.experiences_fraction(), p.learned, p.learned_within, p.views);
  }
  out.table += Format("%-6s %6s %8.3f %12.3f %8d %7d\n", "all", "", f.single_fraction,
                      f.experiences_fraction, f.learned, f.learned_within);
  out.table += Format(
      "single, experiences: fraction of visits (every session after a place's first, in order)\n"
      "whose shift against the taught view is within %.1f px of the truth, from the taught view\n"
      "alone or from the view that matches best, chained by the offsets the route measured when "
      "it\n"
      "learned its views; learned: views learned; within: ... whose stored offset is within it\n",
      f.tolerance_px);
  return out;
}

namespace {

// One scenario and mode of `eval lifelong`: its runs' sessions summed up.
nlohmann::json LifelongRowJson(const std::string& scenario, bool learn,
                               const std::vector<eval::LifelongRun>& runs, int sessions,
                               std::string* table) {
  int successes = 0;
  double views = 0.0;
  double features = 0.0;
  for (const auto& r : runs) {
    successes += r.all_succeeded() ? 1 : 0;
    views += r.route_views;
    features += r.route_features;
  }
  const double n = static_cast<double>(runs.size());
  nlohmann::json row = {{"scenario", scenario},
                        {"learn", learn},
                        {"runs", runs.size()},
                        {"successes", successes},
                        {"route_views", views / n},
                        {"route_features", features / n},
                        {"per_session", nlohmann::json::array()}};
  std::string line = Format("%-18s %-11s %4d/%-3zu", scenario.c_str(),
                            learn ? "experiences" : "single", successes, runs.size());
  double first_rms = 0.0;
  double ratio_max = 0.0;
  for (int s = 1; s <= sessions; ++s) {
    int ok = 0;
    int learned = 0;
    double sum_sq = 0.0;
    for (const auto& r : runs) {
      const eval::LifelongSession& x = r.sessions[static_cast<std::size_t>(s - 1)];
      ok += x.success ? 1 : 0;
      learned += x.learned;
      sum_sq += x.lateral_rms_m * x.lateral_rms_m;
    }
    const double rms = std::sqrt(sum_sq / n);
    if (s == 1) first_rms = rms;
    if (first_rms > 0.0) ratio_max = std::max(ratio_max, rms / first_rms);
    row["per_session"].push_back(
        {{"session", s}, {"successes", ok}, {"lateral_rms_m", rms}, {"learned", learned}});
    line += Format(" %2d", ok);
  }
  row["failures"] = nlohmann::json::array();
  for (std::size_t r = 0; r < runs.size(); ++r)
    for (const auto& x : runs[r].sessions)
      if (!x.success)
        row["failures"].push_back("run " + std::to_string(r + 1) + " session " +
                                  std::to_string(x.session) + ": " + x.status);
  row["lateral_rms_m_session1"] = first_rms;
  row["lateral_rms_ratio_max"] = ratio_max;
  *table += line + Format("  %5.2f %6.1f %8.0f\n", ratio_max, views / n, features / n);
  return row;
}

}  // namespace

SuiteOutput RunLifelongSuite(const SuiteOptions& options) {
  const int sessions = options.sessions;
  std::vector<std::string> names;
  for (const auto& name : eval::LifelongScenarioNames())
    if (options.only.empty() || options.only == name) names.push_back(name);
  if (names.empty() && !options.only.empty()) names.push_back(options.only);  // a file or another
  std::vector<sim::Scenario> scenarios;
  for (const auto& name : names) {
    scenarios.push_back(sim::LoadScenario(name));
    (void)sim::SessionScenario(scenarios.back(), 0);  // refuses a scenario without sessions
  }
  MAPLESS_CHECK(options.method == "funnel" || options.method == "eigenspace",
                "--method " << options.method << ": funnel or eigenspace");
  const bool follow = options.method == "eigenspace";
  // Each scenario taught on session 0 (clean, once), then every run in both modes.
  std::vector<eval::TaughtRoute> taught(scenarios.size());
  std::vector<eval::TaughtAppearance> taught_images(scenarios.size());
  SuiteOptions quiet = options;
  quiet.on_start = nullptr;
  quiet.on_entry_done = nullptr;
  RunInBatches(scenarios.size(), quiet, [&](std::size_t k) {
    const sim::Scenario first = sim::SessionScenario(scenarios[k], 0);
    if (follow) {
      taught_images[k] = eval::TeachAppearanceOnSimulator(first, eval::EigenspaceRunOptions{});
    } else {
      taught[k] = eval::TeachOnSimulator(first, navigation::TeachOptions{});
    }
    return std::string();
  });
  const std::size_t per_mode = static_cast<std::size_t>(options.runs);
  const std::size_t per_scenario = 2 * per_mode;
  std::vector<eval::LifelongRun> results(scenarios.size() * per_scenario);
  RunInBatches(results.size(), options, [&](std::size_t k) {
    const std::size_t sc = k / per_scenario;
    const bool learn = (k % per_scenario) < per_mode;
    eval::LifelongOptions o;
    o.sessions = sessions;
    o.learn = learn;
    o.seed = options.seed + k % per_mode;
    results[k] = follow ? eval::RunLifelongFollow(scenarios[sc], taught_images[sc], o)
                        : eval::RunLifelong(scenarios[sc], taught[sc], o);
    int ok = 0;
    for (const auto& s : results[k].sessions) ok += s.success ? 1 : 0;
    return Format("%s %s run %zu: %d/%d sessions", names[sc].c_str(),
                  learn ? "experiences" : "single", k % per_mode + 1, ok, sessions);
  });
  SuiteOutput out;
  out.json = SuiteJson("lifelong", options.runs, options.seed);
  out.json["sessions"] = sessions;
  out.json["method"] = options.method;
  out.table = Format("%-18s %-11s %8s  successes per session 1..%d, ratio, views, features\n",
                     "scenario", "mode", "all", sessions);
  for (std::size_t sc = 0; sc < scenarios.size(); ++sc) {
    for (const bool learn : {true, false}) {
      const auto first =
          results.begin() + static_cast<std::ptrdiff_t>(sc * per_scenario + (learn ? 0 : per_mode));
      const std::vector<eval::LifelongRun> runs(first,
                                                first + static_cast<std::ptrdiff_t>(per_mode));
      out.json["results"].push_back(LifelongRowJson(names[sc], learn, runs, sessions, &out.table));
    }
  }
  out.table += Format(
      "all: runs that completed every session; then successes on each session; ratio: the\n"
      "largest lateral RMS of a session over session 1's; views, features: the route after the\n"
      "last session (taught views included), mean over runs\n");
  return out;
}

}  // namespace mapless::run
