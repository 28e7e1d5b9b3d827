// `mapless eval SUITE`: reproduce a paper's experiments on the simulator. One subcommand per
// suite, each with its own options; the runs themselves are the run layer's (run/suites.h). One
// JSON object {"suite", "results": [{"scenario", "controller", "runs", "successes",
// "final_error_m_rms", ...}]} with --json, and a readable table.
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>

#include "cli_common.h"
#include "interrupt.h"
#include "mapless/core/check.h"
#include "mapless/run/fleet_eval.h"
#include "mapless/run/generated_suite.h"
#include "mapless/run/report.h"
#include "mapless/run/suites.h"
#include "mapless/sim/generator.h"
#include "progress.h"

namespace mapless::app {

namespace {

struct SuiteArgs {
  run::SuiteOptions suite;
  bool json = false;
};

// The options every simulator suite has.
void AddSuiteOptions(CLI::App* cmd, SuiteArgs* a, bool report = true) {
  cmd->add_option("--runs", a->suite.runs, "Repeats per scenario and controller")
      ->capture_default_str()
      ->check(CLI::Range(1, 1000));
  cmd->add_option("--seed", a->suite.seed, "First seed; run i uses seed + i")
      ->capture_default_str()
      ->check(SeedCheck());
  cmd->add_flag("--json", a->json, "Print one JSON object (the table goes to stderr)");
  cmd->add_option("--jobs", a->suite.jobs, "Scenarios evaluated in parallel")
      ->capture_default_str()
      ->check(CLI::Range(1, 64));
  cmd->add_option("--only", a->suite.only, "Evaluate only this scenario of the suite");
  if (report)
    cmd->add_option("--report", a->suite.report_dir,
                    "Write an HTML report (index.html and PNG plots) into this directory");
}

// The table on stdout, or with --json the JSON there and the table on stderr.
template <typename Output>
void Print(const Output& out, bool json) {
  std::fputs(out.table.c_str(), json ? stderr : stdout);
  if (json) std::cout << out.json.dump() << "\n";
}

// Checks the report directory before any work, shows progress on a terminal, runs, prints.
void RunSuite(SuiteArgs a, const std::function<run::SuiteOutput(const run::SuiteOptions&)>& suite) {
  if (!a.suite.report_dir.empty()) {
    RefuseOutputOverInputs(a.suite.report_dir, "--report", {});
    run::CheckReportDir(a.suite.report_dir, "--report");
  }
  std::unique_ptr<Progress> progress;
  const auto start = std::chrono::steady_clock::now();  // teaching comes before the runs
  a.suite.on_start = [&progress, start](int total) {
    progress = std::make_unique<Progress>("eval", total, start);
  };
  a.suite.on_entry_done = [&progress](const std::string& line) {
    spdlog::info("eval: {}", line);
    progress->Done();
  };
  const run::SuiteOutput out = suite(a.suite);
  progress.reset();
  Print(out, a.json);
  if (!a.suite.report_dir.empty())
    spdlog::info("eval: report in {}/index.html", a.suite.report_dir);
}

// table1, funnel-scenarios, obstacles: the funnel-lane repeat and its options.
void AddRepeatSuite(CLI::App* eval, const std::string& name, const std::string& what) {
  struct Args : SuiteArgs, SwitchingArgs {
    std::string on_obstacle = "stop";
    bool learn = false;
  };
  auto a = std::make_shared<Args>();
  CLI::App* cmd = eval->add_subcommand(name, what);
  AddSuiteOptions(cmd, a.get());
  AddSwitchingOptions(cmd, a.get());
  cmd->add_option("--on-obstacle", a->on_obstacle,
                  "The obstacle watch: stop (as in `repeat`), avoid (go round it; the objects "
                  "added at repeat time then stay for the whole run) or off (the paper's repeat)")
      ->capture_default_str()
      ->check(CLI::IsMember({"stop", "avoid", "off"}));
  cmd->add_flag("--learn", a->learn, "Learn how the route's places look today (each run in turn)");
  cmd->callback([a, name] {
    eval::RepeatRunOptions base;
    a->ApplyTo(&base.repeat);
    base.repeat.obstacle.enabled = a->on_obstacle != "off";
    base.repeat.obstacle.avoid = a->on_obstacle == "avoid";
    base.repeat.learn = a->learn;
    const nlohmann::json settings = {{"switching", a->switching},
                                     {"redetect_every", a->redetect_every},
                                     {"recover_keyframes", a->recover_keyframes},
                                     {"on_obstacle", a->on_obstacle},
                                     {"learn", a->learn},
                                     {"end", a->end}};
    RunSuite(*a, [&](const run::SuiteOptions& o) {
      return run::RunRepeatSuite(name, o, base, settings);
    });
  });
}

// `mapless eval fleet`: its processes, faults and keys.
void AddFleetEvalOptions(CLI::App* eval, run::FleetEvalOptions* a) {
  eval->add_option("--followers", a->followers, "followers")
      ->capture_default_str()
      ->check(CLI::Range(1, 16));
  eval->add_option("--method", a->method, "funnel or eigenspace")->capture_default_str();
  eval->add_option("--scenario", a->scenario,
                   "scenario (default table1_almost_straight / office_aliasing)");
  eval->add_option("--real-time-factor", a->rate, "simulated seconds per wall-clock second")
      ->capture_default_str()
      ->check(FiniteIn(0.1, 20.0));
  AddOldName(eval, "--rate", "--real-time-factor", &a->rate)->check(FiniteIn(0.1, 20.0));
  eval->add_option("--start-after", a->start_after_s,
                   "followers start this many seconds after the leader")
      ->capture_default_str()
      ->check(FiniteIn(0.0, 600.0));
  eval->add_option("--kill-leader-at", a->kill_leader_at_s,
                   "kill the leader (SIGKILL) after this many seconds and start it again")
      ->check(FiniteIn(0.0, 3600.0));
  eval->add_option("--kill-follower-at", a->kill_follower_at_s,
                   "kill follower 1 after this many seconds and start it again")
      ->check(FiniteIn(0.0, 3600.0));
  eval->add_option("--link-down-at", a->link_down_at_s,
                   "cut the last follower's link after this many seconds ...")
      ->check(FiniteIn(0.0, 3600.0));
  eval->add_option("--link-down-for", a->link_down_for_s, "... for this many seconds")
      ->capture_default_str()
      ->check(FiniteIn(0.0, 600.0));
  eval->add_flag("--curve", a->curve, "CURVE keys for the leader and every follower");
  eval->add_option("--keep", a->keep, "keep the routes and logs in this directory");
}

// A directory that will be written later: it must be a directory, or not exist yet under a
// writable one.
void CheckWritableDir(const std::string& dir, const std::string& option) {
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::path p = fs::absolute(dir, ec);
  if (fs::exists(p, ec) && !fs::is_directory(p, ec))
    throw InputError(option + " " + dir + ": is not a directory");
  while (!p.empty() && !fs::exists(p, ec) && p != p.parent_path()) p = p.parent_path();
  if (::access(p.c_str(), W_OK | X_OK) != 0)
    throw InputError(option + " " + dir + ": " + p.string() + " is not writable");
}

// `mapless eval generated`: one method on generated worlds (or on world files, to replay one).
void AddGeneratedSuite(CLI::App* eval) {
  struct Args {
    run::GeneratedSuiteOptions suite;
    bool json = false;
    std::string on_obstacle = "stop";
  };
  auto a = std::make_shared<Args>();
  CLI::App* cmd = eval->add_subcommand(
      "generated", "One method on worlds drawn from seeds (mapless sim generate), each run once");
  cmd->add_option("--method", a->suite.method, "funnel, eigenspace or potential")
      ->capture_default_str()
      ->check(CLI::IsMember({"funnel", "eigenspace", "potential"}));
  cmd->add_option("--worlds", a->suite.worlds, "Worlds, generated from seeds seed .. seed + N - 1")
      ->capture_default_str()
      ->check(CLI::Range(1, 10000));
  cmd->add_option("--seed", a->suite.seed, "First world's seed (also the run's noise seed)")
      ->capture_default_str()
      ->check(SeedCheck());
  cmd->add_option("--kind", a->suite.kind, "Only worlds of this kind (default: drawn per seed)")
      ->check(CLI::IsMember(sim::GeneratorKinds()));
  cmd->add_option("--world", a->suite.world_files,
                  "Run these scenario files instead (a failure's world: replay it with its seed)");
  cmd->add_option("--jobs", a->suite.jobs, "Worlds evaluated in parallel")
      ->capture_default_str()
      ->check(CLI::Range(1, 64));
  cmd->add_option("--max-blocked", a->suite.max_blocked_s,
                  "A stop that does not clear ends the run after this many seconds")
      ->capture_default_str()
      ->check(FiniteIn(1.0, 3600.0));
  cmd->add_option("--on-obstacle", a->on_obstacle,
                  "The obstacle watch of the repeat and the follower: stop, or off (the papers')")
      ->capture_default_str()
      ->check(CLI::IsMember({"stop", "off"}));
  cmd->add_option("--failures", a->suite.failures_dir,
                  "Directory for the worlds of failed runs (created when there is one)")
      ->capture_default_str();
  cmd->add_flag("--json", a->json, "Print one JSON object (the table goes to stderr)");
  cmd->add_option("--report", a->suite.report_dir,
                  "Write an HTML report (index.html, PNG plots, every world's file) here");
  cmd->callback([a] {
    run::GeneratedSuiteOptions o = a->suite;
    o.watch = a->on_obstacle == "stop";
    for (const std::string& f : o.world_files) sim::LoadScenario(f);  // bad input before any work
    if (!o.report_dir.empty()) {
      RefuseOutputOverInputs(o.report_dir, "--report", o.world_files);
      run::CheckReportDir(o.report_dir, "--report");
    }
    if (!o.failures_dir.empty()) {
      RefuseOutputOverInputs(o.failures_dir, "--failures", o.world_files);
      CheckWritableDir(o.failures_dir, "--failures");
    }
    std::unique_ptr<Progress> progress;
    const auto start = std::chrono::steady_clock::now();
    o.on_start = [&progress, start](int total) {
      progress = std::make_unique<Progress>("eval", total, start);
    };
    std::mutex mutex;
    o.on_entry_done = [&progress, &mutex](const std::string& line) {
      const std::lock_guard<std::mutex> lock(mutex);
      spdlog::info("eval: {}", line);
      progress->Done();
    };
    const run::SuiteOutput out = run::RunGeneratedSuite(o);
    progress.reset();
    Print(out, a->json);
    if (!o.report_dir.empty()) spdlog::info("eval: report in {}/index.html", o.report_dir);
  });
}

}  // namespace

void AddEvalCommand(CLI::App* app) {
  CLI::App* eval = app->add_subcommand(
      "eval",
      "Run an evaluation suite on the simulator or on real images: mapless eval SUITE [options]");
  eval->require_subcommand(1);
  AddRealDataEvals(eval);
  AddRepeatSuite(eval, "table1", "Kassir et al., Table I: the funnel lanes on its four routes");
  AddRepeatSuite(eval, "funnel-scenarios",
                 "The funnel-lane repeat on the held-out scenarios (indoor, outdoor, aliasing)");
  AddRepeatSuite(eval, "obstacles",
                 "The funnel-lane repeat with objects put on the route at repeat time");
  AddGeneratedSuite(eval);
  auto potential = std::make_shared<SuiteArgs>();
  CLI::App* p = eval->add_subcommand(
      "potential", "Ohnishi & Imiya, Section 5: corridors, obstacles, destinations and homing");
  AddSuiteOptions(p, potential.get());
  p->callback([potential] { RunSuite(*potential, run::RunPotentialSuite); });
  auto eigenspace = std::make_shared<SuiteArgs>();
  CLI::App* e = eval->add_subcommand(
      "eigenspace", "Payá et al., Section 5: the appearance route follower on its two routes");
  AddSuiteOptions(e, eigenspace.get());
  e->add_flag("--learn", eigenspace->suite.learn,
              "Each entry's runs follow one route in turn, each learning views into it for the "
              "next (follow --learn; not the concurrent entry)");
  e->callback([eigenspace] { RunSuite(*eigenspace, run::RunEigenspaceSuite); });
  auto sessions = std::make_shared<std::pair<std::string, bool>>();
  auto views = std::make_shared<eval::ExperiencesEvalOptions>();
  CLI::App* x = eval->add_subcommand(
      "experiences", "Experiences on real images of places visited in several sessions");
  x->add_option("--sessions", sessions->first, "DIR/SSPP.png and DIR/offsets.txt")->required();
  x->add_option("--max-views", views->experiences.max_views, "Views per place, the taught one too")
      ->capture_default_str()
      ->check(CLI::Range(1, 64));
  x->add_flag("--json", sessions->second, "Print one JSON object (the table goes to stderr)");
  x->callback([sessions, views] {
    Print(run::RunExperiencesEval(sessions->first, *views), sessions->second);
  });
  auto lifelong = std::make_shared<SuiteArgs>();
  CLI::App* l = eval->add_subcommand(
      "lifelong", "Routes taught once and repeated on sessions 1..N of a world that changes");
  AddSuiteOptions(l, lifelong.get(), /*report=*/false);
  l->add_option("--session-count", lifelong->suite.sessions, "Sessions repeated after the teach's")
      ->capture_default_str()
      ->check(CLI::Range(1, 100));
  l->add_option("--method", lifelong->suite.method,
                "funnel (teach and repeat, the views of keyframes) or eigenspace (the appearance "
                "follower, views of route images)")
      ->capture_default_str()
      ->check(CLI::IsMember({"funnel", "eigenspace"}));
  l->callback([lifelong] { RunSuite(*lifelong, run::RunLifelongSuite); });
  auto fleet = std::make_shared<run::FleetEvalOptions>();
  auto fleet_json = std::make_shared<bool>(false);
  CLI::App* f = eval->add_subcommand(
      "fleet", "A leader and followers as processes on loopback, with the faults asked for");
  AddFleetEvalOptions(f, fleet.get());
  f->add_option("--seed", fleet->seed, "Seed of the followers' noise")
      ->capture_default_str()
      ->check(SeedCheck());
  f->add_flag("--json", *fleet_json, "Print one JSON object (the table goes to stderr)");
  f->callback([fleet, fleet_json] {
    run::FleetEvalOptions o = *fleet;
    StopCleanlyOnInterrupt();
    o.each_tick = ThrowIfInterrupted;
    o.say = [](const std::string& line) { spdlog::info("{}", line); };
    const run::FleetEvalOutput out = run::RunFleetEval(o);
    Print(out, *fleet_json);
    if (!out.ok)
      throw RunFailed(
          "eval fleet: a follower failed or its copy differs (logs: rerun with --keep DIR)");
  });
}

}  // namespace mapless::app
