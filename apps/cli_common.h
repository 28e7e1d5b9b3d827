// Shared pieces of the `mapless` subcommands: the run configuration file, pose parsing, and the
// mapping of YAML onto the library's options structs. main() lives in main.cc.
#pragma once

#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <memory>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>

#include "mapless/core/pose.h"
#include "mapless/io/journal.h"
#include "mapless/navigation/repeat.h"
#include "mapless/sim/simulation.h"

namespace mapless::app {

// Exit codes: 0 success, 1 a run that did not succeed (e.g. a collision), 2 bad input or usage.
inline constexpr int kExitRunFailed = 1;
inline constexpr int kExitBadInput = 2;

// Thrown by a subcommand whose run ended without success (the message says why): exit code 1.
class RunFailed : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Parses `n` comma-separated numbers ("X,Y" for n = 2); throws InputError naming the option and
// `form` (what was expected, e.g. "X,Y").
std::vector<double> ParseNumbers(const std::string& text, const std::string& option, int n,
                                 const std::string& form);
// Parses "X,Y,THETA_DEG"; throws InputError naming the option.
Pose2 ParsePoseDeg(const std::string& text, const std::string& option);
// The funnel-lane repeat's switching options, the same in `repeat` and `eval table1|...`.
struct SwitchingArgs {
  std::string switching = "stdratio";
  std::string end = "scale";
  int redetect_every = navigation::RepeatOptions{}.redetect_every_frames;
  int recover_keyframes = navigation::RepeatOptions{}.recovery_keyframes;
  double carry_on_m = navigation::RepeatOptions{}.carry_on.max_distance_m;
  // Into `options`; throws InputError naming a value that is not one (--switching, --end).
  void ApplyTo(navigation::RepeatOptions* options) const;
};
void AddSwitchingOptions(CLI::App* cmd, SwitchingArgs* a);

// Decision logs, one JSON object per line. To a file, each line is a journal record
// (io/journal.h): a run killed at any moment leaves every line it finished, whole.
class JsonLines {
 public:
  // "" or "-": standard output. A file the user names is replaced when the run ends (interrupted
  // or not); until then it stays as it was and the lines go to PATH.partial (io::JournalFile).
  // `in_place`: write PATH directly (files inside an output directory of the run's own).
  explicit JsonLines(const std::string& path, bool in_place = false);
  void Write(const nlohmann::json& j);

 private:
  std::unique_ptr<io::JournalFile> file_;
};

// Options of a simulated run, read from --config FILE (see config/default.yaml).
sim::DriveOptions LoadDriveOptions(const std::string& config_path);

// Drives the scenario's taught path and writes into DIR (new or empty: io::OutputDirectory)
// frames/NNNNNN.png, frames.csv, groundtruth.tum, odometry.tum, topdown.png and summary.json (each
// file atomically; frames as they are rendered: an interrupted run keeps every complete frame).
sim::DriveSummary DriveToDirectory(const sim::Scenario& scenario, const sim::DriveOptions& options,
                                   const std::string& out_dir);

// A CLI11 check for seeds: a whole number 0 .. 2^64 - 1 (CLI11 would wrap "-1" round).
CLI::Validator SeedCheck();

// The old name of a renamed option (one meaning per name, issue 42): it sets the same value and
// warns that the option is now `new_name`; listed in --help under "Old names" (a hidden option's
// errors name no option: CLI11 names hidden options ""), and refused together with `new_name`
// (given both, the old one silently won). Add `new_name` first. Returns it for its checks.
template <typename T>
CLI::Option* AddOldName(CLI::App* cmd, const std::string& old_name, const std::string& new_name,
                        T* value) {
  CLI::Option* old =
      cmd->add_option(old_name, *value, "Old name of " + new_name)
          ->group("Old names")
          ->each([old_name, new_name](const std::string&) {
            spdlog::warn("{} is now {} here; the old name will go", old_name, new_name);
          });
  if (CLI::Option* renamed = cmd->get_option_no_throw(new_name)) old->excludes(renamed);
  return old;
}
// A CLI11 check: a finite number in [lo, hi] (CLI::Range lets nan through).
CLI::Validator FiniteIn(double lo, double hi);
// 0 (a rate's "as fast as it can"), or a finite number in [lo, hi] (a rate of 1e-300 would
// overflow the pacing).
CLI::Validator ZeroOrIn(double lo, double hi);

// Throws InputError naming both unless `output` is a different file from every input and lies
// outside every input directory. `option` names the output's option ("--log").
void RefuseOutputOverInputs(const std::string& output, const std::string& option,
                            const std::vector<std::string>& inputs);

// Registers the subcommands on the app.
void AddSimCommands(CLI::App* app);
void AddDemoCommand(CLI::App* app);
void AddBenchCommand(CLI::App* app);
void AddShiftCommand(CLI::App* app);
void AddEvalCommand(CLI::App* app);
void AddRealDataEvals(CLI::App* eval);  // eval shift, localize, ground
void AddSoakCommand(CLI::App* app);
void AddTeachRepeatCommands(CLI::App* app);
void AddFollowCommand(CLI::App* app);
void AddTeleopCommand(CLI::App* app);
void AddFlowCommand(CLI::App* app);
void AddGroundCommand(CLI::App* app);
void AddNavigateCommand(CLI::App* app);
void AddLocalizeCommand(CLI::App* app);
// Reads an image or throws InputError naming the file.
cv::Mat ReadImageOrThrow(const std::string& path, int flags);

}  // namespace mapless::app
