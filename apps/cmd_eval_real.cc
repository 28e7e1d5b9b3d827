// `mapless eval shift|localize|ground`: mapless and stock baselines on a user's real images, in one
// run (run/real_data.h; the dataset layouts are in docs/real_data.md).
#include <cstdio>
#include <iostream>
#include <memory>

#include "cli_common.h"
#include "mapless/run/real_data.h"

namespace mapless::app {

namespace {

void Print(const run::SuiteOutput& out, bool json) {
  std::fputs(out.table.c_str(), json ? stderr : stdout);
  if (json) std::cout << out.json.dump() << "\n";
}

void AddShiftEval(CLI::App* eval) {
  struct Args {
    std::string dir;
    eval::ShiftEvalOptions options;
    bool json = false;
  };
  auto a = std::make_shared<Args>();
  CLI::App* cmd = eval->add_subcommand(
      "shift", "Horizontal shift across sessions on real images, with stock baselines");
  cmd->add_option("--sessions", a->dir,
                  "DIR/SSPP.png and DIR/offsets.txt, or DIR/summer/, DIR/winter/ and DIR/dx.txt")
      ->required();
  cmd->add_option("--tolerance", a->options.tolerance_px, "A shift is right within this many px")
      ->capture_default_str()
      ->check(FiniteIn(0.1, 1e4));
  cmd->add_flag("--json", a->json, "Print one JSON object (the table goes to stderr)");
  cmd->callback([a] { Print(run::RunShiftEval(a->dir, a->options), a->json); });
}

void AddLocalizeEval(CLI::App* eval) {
  struct Args {
    std::string database;
    std::string query;
    eval::LocalizeEvalOptions options;
    bool json = false;
  };
  auto a = std::make_shared<Args>();
  CLI::App* cmd = eval->add_subcommand(
      "localize", "Localization across seasons on real images, with stock baselines");
  cmd->add_option("--database", a->database, "Route images: a folder, file-name order")->required();
  cmd->add_option("--query", a->query,
                  "Query images: a folder, file-name order; the truth is the database image of "
                  "the same name")
      ->required();
  cmd->add_option("--advance", a->options.filter.advance,
                  "Motion model: database images per query image")
      ->capture_default_str()
      ->check(FiniteIn(0.0, 1000.0));
  cmd->add_option("--advance-sigma", a->options.filter.advance_sigma,
                  "Motion model: its standard deviation per query, database images")
      ->capture_default_str()
      ->check(FiniteIn(0.01, 1000.0));
  cmd->add_option("--start-sigma", a->options.filter.start_sigma,
                  "The queries start within about this many database images of the first (0: "
                  "anywhere)")
      ->capture_default_str()
      ->check(FiniteIn(0.0, 1e6));
  cmd->add_flag("--json", a->json, "Print one JSON object (the table goes to stderr)");
  cmd->callback([a] { Print(run::RunLocalizeEval(a->database, a->query, a->options), a->json); });
}

void AddGroundEval(CLI::App* eval) {
  struct Args {
    std::string frames;
    std::string masks;
    bool json = false;
  };
  auto a = std::make_shared<Args>();
  CLI::App* cmd = eval->add_subcommand(
      "ground", "The ground from optical flow on real images against labels, with a baseline");
  cmd->add_option("--frames", a->frames, "Consecutive frames: a folder, file-name order")
      ->required();
  cmd->add_option("--masks", a->masks,
                  "Ground labels: a folder, one image per frame of the same name (> 127: ground)")
      ->required();
  cmd->add_flag("--json", a->json, "Print one JSON object (the table goes to stderr)");
  cmd->callback([a] {
    Print(run::RunGroundEval(a->frames, a->masks, eval::DefaultGroundEvalOptions()), a->json);
  });
}

}  // namespace

void AddRealDataEvals(CLI::App* eval) {
  AddShiftEval(eval);
  AddLocalizeEval(eval);
  AddGroundEval(eval);
}

}  // namespace mapless::app
