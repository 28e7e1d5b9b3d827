// The `mapless` command line. Subcommands live in cmd_*.cc; this file only dispatches and turns
// exceptions into one clear error line and an exit code (0 ok, 1 run failed, 2 bad input/usage).
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <iostream>
#include <opencv2/core.hpp>
#include <opencv2/core/utils/logger.hpp>
#include <string>

#include "builtin_middlewares.h"
#include "cli_common.h"
#include "fleet.h"
#include "interrupt.h"
#include "mapless/core/check.h"
#include "mapless/core/warning.h"

namespace {

// The error on one line, whatever it quotes: control characters (a newline in a file name) are
// written as escapes.
std::string OneLine(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (const char c : text) {
    const auto u = static_cast<unsigned char>(c);
    if (c == '\n') {
      out += "\\n";
    } else if (c == '\r') {
      out += "\\r";
    } else if (c == '\t') {
      out += "\\t";
    } else if (u < 0x20 || u == 0x7f) {
      char hex[8];
      std::snprintf(hex, sizeof(hex), "\\x%02x", u);
      out += hex;
    } else {
      out += c;
    }
  }
  return out;
}

// `mapless --version`: the version and the robot links this build has.
std::string VersionText() {
  std::string links;
  for (const std::string& n : mapless::app::BuiltinMiddlewares().names())
    links += (links.empty() ? "" : ", ") + n;
  return std::string("mapless ") + MAPLESS_VERSION + "\nrobot links: " +
         (links.empty() ? "none (simulator, recordings, videos and cameras only; "
                          "scripts/setup.sh --ros, then build again, for ROS 1 and ROS 2)"
                        : links);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"mapless: appearance-based robot navigation from one uncalibrated camera, no map"};
  app.require_subcommand(1);
  app.set_version_flag("--version", VersionText());
  // Logs go to stderr: stdout carries only results (JSON, tables, lists).
  spdlog::set_default_logger(spdlog::stderr_color_mt("mapless"));
  spdlog::set_pattern("%^[%l]%$ %v");
  cv::setNumThreads(1);
  // OpenCV's own log lines (video back ends probing a file) would break "one error line": every
  // failure reaches the user as mapless's own message instead.
  cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_SILENT);
  mapless::app::InstallInterruptHandlers();
  mapless::SetWarningSink([](const std::string& line) { spdlog::warn("{}", line); });
  mapless::app::AddDemoCommand(&app);
  mapless::app::AddSimCommands(&app);
  mapless::app::AddTeachRepeatCommands(&app);
  mapless::app::AddFollowCommand(&app);
  mapless::app::AddLeadCommand(&app);
  mapless::app::AddFleetCommand(&app);
  mapless::app::AddShiftCommand(&app);
  mapless::app::AddFlowCommand(&app);
  mapless::app::AddGroundCommand(&app);
  mapless::app::AddNavigateCommand(&app);
  mapless::app::AddLocalizeCommand(&app);
  mapless::app::AddEvalCommand(&app);
  mapless::app::AddSoakCommand(&app);
  mapless::app::AddBenchCommand(&app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::cerr << "mapless: error: " << OneLine(e.what()) << " (see --help)\n";
    return mapless::app::kExitBadInput;
  } catch (const mapless::app::Interrupted& e) {
    std::cerr << "mapless: " << e.what() << ": stopped cleanly, every finished file kept\n";
    return e.exit_code();
  } catch (const mapless::InputError& e) {
    std::cerr << "mapless: error: " << OneLine(e.what()) << "\n";
    return mapless::app::kExitBadInput;
  } catch (const mapless::app::RunFailed& e) {
    std::cerr << "mapless: " << OneLine(e.what()) << "\n";
    return mapless::app::kExitRunFailed;
  } catch (const cv::Exception& e) {
    // Inputs are checked before they reach OpenCV; one that still trips it is a mapless bug.
    std::cerr << "mapless: error: internal (OpenCV " << e.func << "): " << OneLine(e.err)
              << "; please report this with the command line\n";
    return mapless::app::kExitRunFailed;
  } catch (const std::exception& e) {
    std::cerr << "mapless: error: " << OneLine(e.what()) << "\n";
    return mapless::app::kExitRunFailed;
  }
  return 0;
}
