// The evaluation suites of `mapless eval SUITE` (eval/): each scenario's runs in parallel batches,
// the results as one JSON object and a table, and with a report directory the HTML report with
// the first run of each entry frame by frame (report.h, traces.h). The command parses a suite's
// options and calls one of these.
#pragma once

#include <cstdint>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>

#include "mapless/eval/experiences.h"
#include "mapless/eval/teach_repeat.h"

namespace mapless::run {

struct SuiteOptions {
  int runs = 10;
  std::uint64_t seed = 1;         // run i uses seed + i
  int jobs = 1;                   // entries evaluated in parallel (the results do not depend on it)
  std::string only;               // only this scenario of the suite
  std::string report_dir;         // "" : no report
  int sessions = 20;              // eval lifelong: sessions repeated after the teach's
  std::string method = "funnel";  // eval lifelong: funnel (repeat) or eigenspace (follow)
  bool learn = false;  // eval eigenspace: the runs follow one route in turn, each learning into it
  // Called once with the number of entries, then once per entry done (from any thread).
  std::function<void(int total)> on_start;
  std::function<void(const std::string& line)> on_entry_done;
};

struct SuiteOutput {
  nlohmann::json json;  // {"suite", "runs", "seed", "results": [...], ...}
  std::string table;    // the readable table, one line per entry
};

// table1, funnel-scenarios or obstacles: the funnel-lane repeat with `base`'s options (each
// scenario taught once). `settings`: the repeat options as the command named them, into the JSON.
SuiteOutput RunRepeatSuite(const std::string& suite, const SuiteOptions& options,
                           const eval::RepeatRunOptions& base, const nlohmann::json& settings);
// Ohnishi & Imiya, Section 5, and the inclusion of the hierarchical planes (Table 1).
SuiteOutput RunPotentialSuite(const SuiteOptions& options);
// Payá et al., Section 5.
SuiteOutput RunEigenspaceSuite(const SuiteOptions& options);
// Experiences on real multi-session images (eval/experiences.h): {"suite": "experiences",
// "sessions", "single_fraction", "experiences_fraction", "learned", "learned_within",
// "places": [...]}.
SuiteOutput RunExperiencesEval(const std::string& sessions_dir,
                               const eval::ExperiencesEvalOptions& options);
// Routes that last (eval/lifelong.h): each changing-world scenario taught on session 0 and
// repeated on sessions 1..`options.sessions` in order, `options.runs` times, with experiences and
// with the taught views alone: {"suite": "lifelong", "sessions", "results": [{"scenario", "learn",
// "runs", "successes", "route_views", "route_features", "lateral_rms_ratio_max", "per_session":
// [...]}]}. With options.method "eigenspace", the appearance follower on the same worlds
// (eval::RunLifelongFollow; "method": "eigenspace", route_features 0).
SuiteOutput RunLifelongSuite(const SuiteOptions& options);

}  // namespace mapless::run
